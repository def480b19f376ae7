//! Keyword arguments as a request of `pipeline::request`: each value turned into JSON and
//! the request filled by name, as the schema declares it; the limits every job takes and the
//! progress function set apart; an unknown name a TypeError listing the names.

use super::to_py_err;
use crate::pipeline::request::{LimitsRequest, Schema};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyString};
use serde_json::{Map, Value};

/// The keyword that takes the progress function (not an option of the request).
const PROGRESS: &str = "progress";

/// A keyword's value as JSON: booleans, integers (numpy's too), finite floats, strings and
/// sequences of these. `None` is left to the caller (it means the default).
fn to_json(v: &Bound<'_, PyAny>) -> Result<Value, String> {
    if v.is_instance_of::<PyBool>() {
        return Ok(Value::Bool(v.extract::<bool>().unwrap_or_default()));
    }
    if v.is_instance_of::<PyString>() {
        return v
            .extract::<String>()
            .map(Value::String)
            .map_err(|e| e.to_string());
    }
    if let Ok(n) = v.extract::<i64>() {
        return Ok(Value::from(n));
    }
    if let Ok(x) = v.extract::<f64>() {
        return serde_json::Number::from_f64(x)
            .map(Value::Number)
            .ok_or_else(|| format!("must be a finite number, not {x}"));
    }
    if let Ok(b) = v.extract::<bool>() {
        return Ok(Value::Bool(b));
    }
    if let Ok(items) = v.try_iter() {
        return items
            .map(|item| item.map_err(|e| e.to_string()).and_then(|i| to_json(&i)))
            .collect::<Result<Vec<_>, _>>()
            .map(Value::Array);
    }
    Err(format!(
        "cannot take a {}",
        v.get_type()
            .name()
            .map_or("value".into(), |n| n.to_string())
    ))
}

/// A field that takes names (`grids`, `attributes`) given one string: its comma-separated
/// names, as the command line reads them (`grids="density,Cd"`, `attributes="all"`).
fn names_of_one_string<R: Schema>(key: &str, json: Value) -> Value {
    let names = ["Sequence[str]", "Optional[Sequence[str]]"];
    let takes_names = R::fields()
        .iter()
        .any(|f| f.name == key && names.contains(&f.python_type.as_str()));
    match json {
        Value::String(s) if takes_names => Value::Array(
            s.split(',')
                .map(|n| Value::String(n.trim().into()))
                .collect(),
        ),
        other => other,
    }
}

/// One call's request, limits and progress function, from its keyword arguments.
pub(super) struct Keywords<R> {
    pub(super) request: R,
    pub(super) limits: LimitsRequest,
    pub(super) progress: Option<Py<PyAny>>,
}

impl<R: Schema> Keywords<R> {
    pub(super) fn new(options: Option<&Bound<'_, PyDict>>) -> PyResult<Keywords<R>> {
        let own: Vec<&str> = R::fields().iter().map(|f| f.name).collect();
        let limits: Vec<&str> = LimitsRequest::fields().iter().map(|f| f.name).collect();
        let (mut fields, mut limit_fields) = (Map::new(), Map::new());
        let mut progress = None;
        for (key, value) in options.into_iter().flatten() {
            let key: String = key.extract()?;
            let into = if key == PROGRESS {
                progress = (!value.is_none()).then(|| value.unbind());
                continue;
            } else if own.contains(&key.as_str()) {
                &mut fields
            } else if limits.contains(&key.as_str()) {
                &mut limit_fields
            } else {
                return Err(PyTypeError::new_err(format!(
                    "{}() got an unexpected keyword argument '{key}' (it takes {})",
                    R::NAME,
                    [own.as_slice(), limits.as_slice(), &[PROGRESS]]
                        .concat()
                        .join(", ")
                )));
            };
            if value.is_none() {
                continue;
            }
            let json = to_json(&value).map_err(|e| PyValueError::new_err(format!("{key}: {e}")))?;
            let json = names_of_one_string::<R>(&key, json);
            into.insert(key, json);
        }
        Ok(Keywords {
            request: R::from_json(Value::Object(fields)).map_err(to_py_err)?,
            limits: LimitsRequest::from_json(Value::Object(limit_fields)).map_err(to_py_err)?,
            progress,
        })
    }
}
