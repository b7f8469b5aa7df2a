//! The network file format, `dnnevo-network` version 1 (JSON), and atomic file writes.
//!
//! ```json
//! {"format": "dnnevo-network", "version": 1,
//!  "tau": [1.0, 2.0], "theta": [0.0, 0.5],
//!  "weights": [[0.0, 1.0], [-1.0, 0.0]], "sensor_weights": [[0.5], [0.0]],
//!  "state": [0.0, 0.0],
//!  "integrator": {"method": "euler", "dt": 0.1, "substeps": 10},
//!  "meta": {"task": "sequence-1bit", "seed": 3}}
//! ```
//!
//! `state`, `integrator` and `meta` are optional. Floats are written in their shortest form that
//! reads back to the same bits, so a file round-trips exactly. Python reads and writes files
//! through this module too, so both produce the same bytes. The schema is `docs/network.schema.json`.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use crate::error::{Error, Result};
use crate::integrate::Integrator;
use crate::network::Network;

/// The value of the `format` field.
pub const FORMAT: &str = "dnnevo-network";
/// The version this crate writes and reads.
pub const VERSION: u64 = 1;

/// A network together with the optional parts of its file.
#[derive(Clone, Debug, PartialEq)]
pub struct NetworkFile {
    /// The network, including its state.
    pub network: Network,
    /// How the network is meant to be integrated, if recorded.
    pub integrator: Option<Integrator>,
    /// Free-form facts: task, seed, generation, fitness, dnnevo version, input/output labels.
    pub meta: Map<String, Value>,
}

impl NetworkFile {
    /// A file holding just `network`.
    pub fn new(network: Network) -> Self {
        NetworkFile {
            network,
            integrator: None,
            meta: Map::new(),
        }
    }
}

/// The document as it is stored.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Document {
    format: String,
    version: u64,
    tau: Vec<f64>,
    theta: Vec<f64>,
    weights: Vec<Vec<f64>>,
    sensor_weights: Vec<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    state: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    integrator: Option<Integrator>,
    #[serde(default, skip_serializing_if = "Map::is_empty")]
    meta: Map<String, Value>,
}

/// Serialises `file` as pretty-printed JSON.
///
/// # Example
/// ```
/// use ctrnn::{io, Network};
/// let net = Network::new(vec![1.5], vec![0.1], vec![0.3], vec![], None).unwrap();
/// let text = io::to_json(&io::NetworkFile::new(net.clone()));
/// assert_eq!(io::from_json(&text).unwrap().network, net);
/// ```
pub fn to_json(file: &NetworkFile) -> String {
    let net = &file.network;
    let (n, m) = (net.size(), net.n_inputs());
    let rows = |flat: &[f64], cols: usize| -> Vec<Vec<f64>> {
        (0..n)
            .map(|i| flat[i * cols..(i + 1) * cols].to_vec())
            .collect()
    };
    let doc = Document {
        format: FORMAT.into(),
        version: VERSION,
        tau: net.tau().to_vec(),
        theta: net.theta().to_vec(),
        weights: rows(net.weights(), n),
        sensor_weights: rows(net.sensor_weights(), m),
        state: Some(net.state().to_vec()),
        integrator: file.integrator,
        meta: file.meta.clone(),
    };
    serde_json::to_string_pretty(&doc).expect("a document of finite floats always serialises")
}

/// Parses and validates a network document. Every failure is [`Error::Format`], naming the field.
pub fn from_json(text: &str) -> Result<NetworkFile> {
    let value = serde_json::from_str::<Unique>(text)
        .map_err(|e| json_error(text, &e))?
        .0;
    let obj = value
        .as_object()
        .ok_or_else(|| Error::Format("the document is not a JSON object".into()))?;
    match obj.get("format") {
        Some(Value::String(s)) if s == FORMAT => {}
        Some(other) => {
            return Err(Error::Format(format!(
                "format is {other}; expected \"{FORMAT}\""
            )))
        }
        None => {
            return Err(Error::Format(format!(
                "missing field `format`; expected \"{FORMAT}\""
            )))
        }
    }
    match obj.get("version") {
        Some(v) if v.as_u64() == Some(VERSION) => {}
        Some(v) => {
            return Err(Error::Format(format!(
                "version is {v}; this dnnevo reads version {VERSION}"
            )))
        }
        None => {
            return Err(Error::Format(format!(
                "missing field `version`; expected {VERSION}"
            )))
        }
    }
    if let Some(key) = ["bias", "biases", "gain", "gains"]
        .into_iter()
        .find(|k| obj.contains_key(*k))
    {
        return Err(Error::Format(format!(
            "unknown field `{key}`: this format has thresholds, theta = -bias, and no gains (a \
             gain folds into theta and the weights; docs/network-format.md)"
        )));
    }
    let doc: Document = serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        if path == "." {
            Error::Format(inner.to_string())
        } else {
            Error::Format(format!("{path}: {inner}"))
        }
    })?;
    let n = doc.tau.len();
    let flatten = |field: &str, rows: Vec<Vec<f64>>, cols: Option<usize>| -> Result<Vec<f64>> {
        if rows.len() != n {
            return Err(Error::Format(format!(
                "{field} has {}; expected N = {n} (the length of tau)",
                crate::error::counted(rows.len(), "row")
            )));
        }
        let cols = cols.unwrap_or_else(|| rows.first().map_or(0, Vec::len));
        if let Some(i) = rows.iter().position(|r| r.len() != cols) {
            return Err(Error::Format(format!(
                "{field}[{i}] has {}; expected {cols}",
                crate::error::counted(rows[i].len(), "value")
            )));
        }
        Ok(rows.concat())
    };
    let weights = flatten("weights", doc.weights, Some(n))?;
    let sensor_weights = flatten("sensor_weights", doc.sensor_weights, None)?;
    if let Some(integ) = &doc.integrator {
        integ
            .validate()
            .map_err(|e| Error::Format(format!("integrator: {}", strip(e))))?;
    }
    if let Some(problem) = meta_problem(&doc.meta) {
        return Err(Error::Format(problem));
    }
    let network = Network::new(doc.tau, doc.theta, weights, sensor_weights, doc.state)
        .map_err(|e| Error::Format(strip(e)))?;
    Ok(NetworkFile {
        network,
        integrator: doc.integrator,
        meta: doc.meta,
    })
}

/// A JSON value read with every object's keys checked to be distinct: `serde_json::Value` keeps
/// the last of two equal keys, so `{"tau": [1], "tau": [2]}` would be read as `[2]` silently.
struct Unique(Value);

impl<'de> Deserialize<'de> for Unique {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        d.deserialize_any(UniqueVisitor).map(Unique)
    }
}

struct UniqueVisitor;

impl<'de> serde::de::Visitor<'de> for UniqueVisitor {
    type Value = Value;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E>(self, v: bool) -> std::result::Result<Value, E> {
        Ok(Value::Bool(v))
    }
    fn visit_i64<E>(self, v: i64) -> std::result::Result<Value, E> {
        Ok(v.into())
    }
    fn visit_u64<E>(self, v: u64) -> std::result::Result<Value, E> {
        Ok(v.into())
    }
    fn visit_f64<E>(self, v: f64) -> std::result::Result<Value, E> {
        Ok(serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number))
    }
    fn visit_str<E>(self, v: &str) -> std::result::Result<Value, E> {
        Ok(Value::String(v.to_owned()))
    }
    fn visit_string<E>(self, v: String) -> std::result::Result<Value, E> {
        Ok(Value::String(v))
    }
    fn visit_unit<E>(self) -> std::result::Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(
        self,
        mut seq: A,
    ) -> std::result::Result<Value, A::Error> {
        let mut out = Vec::new();
        while let Some(Unique(v)) = seq.next_element()? {
            out.push(v);
        }
        Ok(Value::Array(out))
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(
        self,
        mut map: A,
    ) -> std::result::Result<Value, A::Error> {
        let mut out = Map::new();
        while let Some(key) = map.next_key::<String>()? {
            if out.contains_key(&key) {
                return Err(serde::de::Error::custom(format!(
                    "the key \"{key}\" appears twice in one object"
                )));
            }
            let Unique(v) = map.next_value()?;
            out.insert(key, v);
        }
        Ok(Value::Object(out))
    }
}

/// `not valid JSON: ...`, saying so when the text there is a NaN or an infinity, which JSON has
/// no words for (Python's `json` writes them, and every value of a network must be finite).
fn json_error(text: &str, e: &serde_json::Error) -> Error {
    if text.starts_with('\u{feff}') {
        return Error::Format(
            "not valid JSON: the text starts with a byte-order mark (U+FEFF), as some editors \
             write; save it as UTF-8 without one"
                .into(),
        );
    }
    let line = text.lines().nth(e.line().saturating_sub(1)).unwrap_or("");
    let column = e.column().saturating_sub(1);
    let at = line.get(column..).unwrap_or("");
    // The error stands after the sign of `-Infinity`.
    let signed = column > 0 && line.get(column - 1..column) == Some("-");
    let word = ["NaN", "Infinity"]
        .into_iter()
        .find(|w| at.starts_with(w))
        .map(|w| {
            if signed {
                format!("-{w}")
            } else {
                w.to_string()
            }
        });
    Error::Format(match word {
        Some(w) => format!(
            "not valid JSON: {w} at line {} column {}; a network's numbers must be finite, and JSON has no NaN or Infinity",
            e.line(),
            e.column()
        ),
        None => format!("not valid JSON: {e}"),
    })
}

/// The conventional keys of `meta` (docs/network-format.md), checked for their type when
/// present, as the schema checks them; any other key may hold anything. The problem, if any.
fn meta_problem(meta: &Map<String, Value>) -> Option<String> {
    type Check = fn(&Value) -> bool;
    // JSON Schema's integer: a number with no fraction, so 3.0 counts.
    let whole: Check =
        |v| v.as_u64().is_some() || v.as_f64().is_some_and(|x| x >= 0.0 && x.fract() == 0.0);
    let strings: Check = |v| v.as_array().is_some_and(|a| a.iter().all(Value::is_string));
    let precision: Check = |v| v.as_str().is_some_and(|p| p == "f64" || p == "f32");
    let rules: [(&str, &str, Check); 8] = [
        ("task", "a string", Value::is_string),
        ("seed", "an integer >= 0", whole),
        ("generation", "an integer >= 0", whole),
        ("fitness", "a number", Value::is_number),
        ("dnnevo_version", "a string", Value::is_string),
        ("input_labels", "a list of strings", strings),
        ("output_labels", "a list of strings", strings),
        ("precision", "\"f64\" or \"f32\"", precision),
    ];
    for (key, what, ok) in rules {
        if let Some(v) = meta.get(key) {
            if !ok(v) {
                return Some(format!("meta.{key} is {v}; expected {what}"));
            }
        }
    }
    None
}

/// The message of an error without its category prefix.
pub(crate) fn strip(e: Error) -> String {
    match e {
        Error::InvalidNetwork(m) | Error::InvalidArgument(m) => m,
        other => other.to_string(),
    }
}

/// Writes `file` to `path` (a `&str`, `&Path` or `PathBuf`) atomically.
pub fn save(path: impl AsRef<Path>, file: &NetworkFile) -> Result<()> {
    let path = path.as_ref();
    // A file that `load` would refuse is not written: meta's conventional keys are named here,
    // and anything else (a NaN dt, which JSON writes as null) by reading the text back.
    if let Some(problem) = meta_problem(&file.meta) {
        return Err(Error::InvalidArgument(problem));
    }
    let mut text = to_json(file);
    if let Err(Error::Format(problem)) = from_json(&text) {
        return Err(Error::InvalidArgument(format!(
            "not written, since it would not load: {problem}"
        )));
    }
    text.push('\n');
    write_atomic(path, text.as_bytes())
}

/// Parses and validates a network file's bytes: [`from_json`], after checking they are UTF-8
/// text. Every failure is [`Error::Format`], so damaged content is never mistaken for an I/O
/// error.
///
/// # Example
/// ```
/// let e = ctrnn::io::from_bytes(b"{\"format\": \"dnnevo-net\xffwork\"}").unwrap_err();
/// assert_eq!(e.to_string(), "invalid file: not UTF-8 text (byte 22)");
/// ```
pub fn from_bytes(bytes: &[u8]) -> Result<NetworkFile> {
    let text = std::str::from_utf8(bytes)
        .map_err(|e| Error::Format(format!("not UTF-8 text (byte {})", e.valid_up_to())))?;
    from_json(text)
}

/// Reads and validates the network file at `path`. A file that cannot be read is
/// [`Error::Io`]; one whose content is not a network file (not UTF-8 included) is
/// [`Error::Format`], naming the path. `path` is a `&str`, `&Path` or `PathBuf`.
///
/// # Example
/// ```
/// let e = ctrnn::io::load("no-such-network.json").unwrap_err();
/// assert!(e.to_string().contains("cannot read no-such-network.json"));
/// ```
pub fn load(path: impl AsRef<Path>) -> Result<NetworkFile> {
    let path = path.as_ref();
    let bytes = fs::read(path).map_err(|source| Error::Io {
        context: format!("cannot read {}", path.display()),
        source,
    })?;
    from_bytes(&bytes).map_err(|e| match e {
        Error::Format(m) => Error::Format(format!("{}: {m}", path.display())),
        other => other,
    })
}

/// Writes `bytes` to a temporary file beside `path`, flushes it to disk, then renames it over
/// `path`, so a reader sees the old file or the new one, never a torn one.
///
/// The temporary file is `.NAME.RANDOM.tmp`, created exclusively (`O_EXCL`): a file or symlink
/// planted under that name makes the attempt fail and another name is tried, so the write never
/// goes through a symlink. It gets mode 0666 & ~umask, like any new file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let io_err = |what: &str, source| Error::Io {
        context: format!("cannot {what} {}", path.display()),
        source,
    };
    let name = path
        .file_name()
        .ok_or_else(|| Error::InvalidArgument(format!("{} is not a file path", path.display())))?;
    let (tmp, mut f) = create_temp(path, name).map_err(|e| io_err("write", e))?;
    let result = (|| {
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = fs::remove_file(&tmp);
        return Err(io_err("write", e));
    }
    Ok(())
}

/// A new temporary file beside `path`, created exclusively under a random name.
fn create_temp(path: &Path, name: &std::ffi::OsStr) -> std::io::Result<(PathBuf, fs::File)> {
    use std::hash::{BuildHasher, Hasher};
    let mut last = None;
    for attempt in 0..16u32 {
        // RandomState is keyed from the operating system's randomness.
        let mut h = std::collections::hash_map::RandomState::new().build_hasher();
        h.write_u32(std::process::id());
        h.write_u32(attempt);
        let mut tmp_name = std::ffi::OsString::from(".");
        tmp_name.push(name);
        tmp_name.push(format!(".{:016x}.tmp", h.finish()));
        let tmp = path.with_file_name(tmp_name);
        match fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
        {
            Ok(f) => return Ok((tmp, f)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => last = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last.unwrap_or_else(|| std::io::Error::other("no free temporary name")))
}
