//! How the CLI talks back: progress bars, the one-line summary and `--json` objects.

use indicatif::{ProgressBar, ProgressStyle};
use std::fmt::Write as _;

/// A progress bar on stderr (hidden when `quiet` or when stderr is not a terminal).
pub fn progress_bar(total: u64, what: &str, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template(
            "{msg:>12} [{bar:40}] {percent:>3}% {elapsed_precise} eta {eta}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}

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
    pub fn obj(self, key: &str, v: Json) -> Self {
        self.put(key, Value::Raw(v.render()))
    }
    pub fn arr(self, key: &str, items: Vec<Json>) -> Self {
        let inner: Vec<String> = items.iter().map(Json::render).collect();
        self.put(key, Value::Raw(format!("[{}]", inner.join(","))))
    }

    /// The closing fields of every voxelizing command.
    pub fn timings(self, voxelize_seconds: f64, seconds: f64) -> Self {
        self.num("voxelize_seconds", voxelize_seconds)
            .num("seconds", seconds)
            .num("peak_mib", peak_mib())
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

/// Peak resident memory in MiB (0 when unknown).
pub fn peak_mib() -> f64 {
    voxelkit::system::peak_memory_bytes().unwrap_or(0) as f64 / (1 << 20) as f64
}
