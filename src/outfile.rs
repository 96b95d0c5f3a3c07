//! A file of an output folder as plain data (the facade writes none itself), and the
//! number form its CSV files use.

/// A file to write: its name inside the output folder and its bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OutFile {
    /// The file name, such as `policy.json`.
    pub name: String,
    /// The whole contents.
    pub contents: Vec<u8>,
}

impl OutFile {
    /// A file from text.
    pub fn text(name: impl Into<String>, text: String) -> OutFile {
        OutFile { name: name.into(), contents: text.into_bytes() }
    }
}

/// `v` in the shortest form that reads back to the same double (`inf`, `-inf`, `NaN` as
/// such).
pub fn number(v: f64) -> String {
    match serde_json::Number::from_f64(v) {
        Some(n) => n.to_string(),
        None if v.is_nan() => "NaN".into(),
        None if v > 0.0 => "inf".into(),
        None => "-inf".into(),
    }
}
