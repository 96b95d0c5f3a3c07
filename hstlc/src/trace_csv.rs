//! Reading traces from CSV files for `hstlc monitor`.
//!
//! The header names the columns; every state variable of the spec must be one of them, other
//! columns are ignored. Values are decimal numbers, `inf` or `-inf`. Fields are separated by
//! commas and trimmed; quotes around a header name are removed.

use std::fmt;

use hstl::robustness::Trace;

/// A problem in a CSV file, with its 1-based line and column (in characters).
#[derive(Debug, PartialEq)]
pub struct CsvError {
    /// 1-based line.
    pub line: usize,
    /// 1-based column, in characters.
    pub column: usize,
    /// What is wrong.
    pub message: String,
    /// How to fix it.
    pub help: Option<String>,
}

impl fmt::Display for CsvError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}: {}", self.line, self.column, self.message)
    }
}

/// Reads `text` into a trace whose column `i` is `vars[i]`.
pub fn read_trace(text: &str, vars: &[&str]) -> Result<Trace, CsvError> {
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    let Some((header_line, header)) = lines.next() else {
        return Err(CsvError {
            line: 1,
            column: 1,
            message: "the file is empty".into(),
            help: Some(format!(
                "the first line must name the columns, such as `{}`",
                vars.join(",")
            )),
        });
    };
    let names: Vec<String> = fields(header).map(|(_, f)| f.trim_matches('"').to_string()).collect();
    let mut picks = Vec::with_capacity(vars.len());
    for var in vars {
        match names.iter().position(|n| n == var) {
            Some(i) => picks.push(i),
            None => {
                return Err(CsvError {
                    line: header_line + 1,
                    column: 1,
                    message: format!("missing column `{var}`"),
                    help: Some(format!(
                        "the header has {}; the spec's state variables are {}",
                        quote_list(names.iter().map(String::as_str)),
                        quote_list(vars.iter().copied())
                    )),
                });
            }
        }
    }
    let mut columns = vec![Vec::new(); vars.len()];
    let mut row = Vec::with_capacity(names.len());
    let mut rows = 0;
    for (i, line) in lines {
        rows += 1;
        row.clear();
        row.extend(fields(line));
        if row.len() != names.len() {
            let column =
                if row.len() > names.len() { row[names.len()].0 } else { line.chars().count() + 1 };
            return Err(CsvError {
                line: i + 1,
                column,
                message: format!(
                    "this row has {}, the header has {}",
                    fields_word(row.len()),
                    names.len()
                ),
                help: Some("every row needs one value per header column".into()),
            });
        }
        for (col, &pick) in columns.iter_mut().zip(&picks) {
            let (column, field) = row[pick];
            col.push(parse_value(field).ok_or_else(|| CsvError {
                line: i + 1,
                column,
                message: format!("`{field}` in column `{}` is not a number", names[pick]),
                help: Some("write a decimal number such as `3`, `-0.5` or `1e-3`, or `inf`".into()),
            })?);
        }
    }
    if rows == 0 {
        return Err(CsvError {
            line: header_line + 1,
            column: 1,
            message: "the trace has no samples".into(),
            help: Some("add one row per time step below the header".into()),
        });
    }
    Trace::from_columns(columns).map_err(|e| CsvError {
        line: 1,
        column: 1,
        message: e.to_string(),
        help: None,
    })
}

/// The fields of one line with the 1-based character column where each starts, trimmed.
fn fields(line: &str) -> impl Iterator<Item = (usize, &str)> {
    let mut column = 1;
    line.split(',').map(move |raw| {
        let lead = raw.chars().take_while(|c| c.is_whitespace()).count();
        let start = column + lead;
        column += raw.chars().count() + 1;
        (start, raw.trim())
    })
}

/// A finite number, `inf` or `-inf`. NaN has no robustness meaning and is refused.
fn parse_value(field: &str) -> Option<f64> {
    let v: f64 = field.parse().ok()?;
    (!v.is_nan()).then_some(v)
}

fn fields_word(n: usize) -> String {
    if n == 1 { "1 field".into() } else { format!("{n} fields") }
}

fn quote_list<'a>(items: impl Iterator<Item = &'a str>) -> String {
    items.map(|s| format!("`{s}`")).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> (usize, usize, String) {
        let e = read_trace(text, &["x", "y"]).unwrap_err();
        (e.line, e.column, e.message)
    }

    #[test]
    fn reads_named_columns_in_spec_order() {
        let t = read_trace("t,y,x\n0,1,2\n1,3,-inf\n", &["x", "y"]).unwrap();
        assert_eq!(t.column(0), &[2.0, f64::NEG_INFINITY]);
        assert_eq!(t.column(1), &[1.0, 3.0]);
    }

    #[test]
    fn locates_bad_input() {
        assert_eq!(err(""), (1, 1, "the file is empty".into()));
        assert_eq!(err("x,z\n1,2\n"), (1, 1, "missing column `y`".into()));
        assert_eq!(err("x,y\n1, oops\n"), (2, 4, "`oops` in column `y` is not a number".into()));
        assert_eq!(err("x,y\n1,2\n1\n"), (3, 2, "this row has 1 field, the header has 2".into()));
        assert_eq!(err("x,y\n1,2,3\n"), (2, 5, "this row has 3 fields, the header has 2".into()));
        assert_eq!(err("x,y\n"), (1, 1, "the trace has no samples".into()));
        assert_eq!(err("x,y\nNaN,1\n"), (2, 1, "`NaN` in column `x` is not a number".into()));
    }
}
