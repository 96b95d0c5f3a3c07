//! A file of an output folder as plain data ([`OutFile`], from `hstl-files`, which writes
//! it; the facade writes none itself), and the number form its CSV files use.

pub use hstl_files::OutFile;

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
