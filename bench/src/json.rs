//! The benchmarks' `--json` objects: ordered keys, as the tables print them.

use std::fmt::Write as _;

/// A JSON value rendered as text.
pub enum Value {
    Num(f64),
    Int(u64),
    Str(String),
    Raw(String),
}

/// An ordered JSON object (keys are ours, values escaped here).
#[derive(Default)]
pub struct Json(Vec<(String, Value)>);

impl Json {
    pub fn put(mut self, key: &str, v: Value) -> Self {
        self.0.push((key.to_string(), v));
        self
    }
    pub fn num(self, key: &str, v: f64) -> Self {
        self.put(key, Value::Num(v))
    }
    pub fn int(self, key: &str, v: u64) -> Self {
        self.put(key, Value::Int(v))
    }
    pub fn str(self, key: &str, v: impl Into<String>) -> Self {
        self.put(key, Value::Str(v.into()))
    }
    pub fn arr(self, key: &str, items: Vec<Json>) -> Self {
        let inner: Vec<String> = items.iter().map(Json::render).collect();
        self.put(key, Value::Raw(format!("[{}]", inner.join(","))))
    }

    pub fn render(&self) -> String {
        let mut s = String::from("{");
        for (i, (k, v)) in self.0.iter().enumerate() {
            if i > 0 {
                s.push(',');
            }
            let _ = write!(s, "{}:", quote(k));
            match v {
                Value::Num(x) if x.is_finite() => {
                    let _ = write!(s, "{x}");
                }
                Value::Num(_) => s.push_str("null"),
                Value::Int(x) => {
                    let _ = write!(s, "{x}");
                }
                Value::Str(x) => s.push_str(&quote(x)),
                Value::Raw(x) => s.push_str(x),
            }
        }
        s.push('}');
        s
    }
}

fn quote(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}
