//! The compact parts of the `policy.json` document: a state `{VAR: value, ...}` held as
//! its values beside names shared by every state of the document, and a Q-table held as
//! its values and written as the 16 hex digits of each one's bits. Both read in the one
//! typed pass over the document, so that a policy in memory costs about what its numbers
//! do, not a map or a string per number.

use std::cell::RefCell;
use std::fmt;
use std::sync::Arc;

use serde::de::{self, MapAccess, SeqAccess, Visitor};
use serde::ser::{SerializeMap, SerializeSeq};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// A state in `policy.json`: `{VAR: value, ...}`, its names in sorted order (as the
/// document writes them) and its values in the same order. The names are shared (one
/// allocation for every state of a document), so a state costs its values.
#[derive(Clone)]
pub struct State {
    names: Arc<[String]>,
    values: Box<[f64]>,
}

thread_local! {
    /// The names of the last state read on this thread: the next state with the same
    /// names shares them.
    static LAST_NAMES: RefCell<Option<Arc<[String]>>> = const { RefCell::new(None) };
}

/// The names `sorted` as a shared list: the last one read or made on this thread when
/// they are equal, so that every state of a document shares one list.
fn shared_names(sorted: &[&str]) -> Arc<[String]> {
    LAST_NAMES.with(|last| {
        let mut last = last.borrow_mut();
        if let Some(names) = last.as_ref()
            && names.len() == sorted.len()
            && names.iter().zip(sorted).all(|(a, b)| a == b)
        {
            return Arc::clone(names);
        }
        let names: Arc<[String]> = sorted.iter().map(|s| s.to_string()).collect();
        *last = Some(Arc::clone(&names));
        names
    })
}

impl State {
    /// The state with `values[i]` for variable `vars[i]` (in any order; the names must
    /// differ).
    pub fn new(vars: &[String], values: &[f64]) -> State {
        let mut order: Vec<usize> = (0..vars.len().min(values.len())).collect();
        order.sort_by(|&a, &b| vars[a].cmp(&vars[b]));
        let sorted: Vec<&str> = order.iter().map(|&i| vars[i].as_str()).collect();
        State { names: shared_names(&sorted), values: order.iter().map(|&i| values[i]).collect() }
    }

    /// The value of variable `name`, if the state has it.
    pub fn get(&self, name: &str) -> Option<f64> {
        let i = self.names.binary_search_by(|n| n.as_str().cmp(name)).ok()?;
        self.values.get(i).copied()
    }

    /// The variables' names, sorted.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The values, in the order of [`State::names`].
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The bits of the values (`-0` read as `0`), in the order of the names: equal for
    /// states that name the same point.
    pub fn bits(&self) -> Vec<u64> {
        self.values.iter().map(|v| (v + 0.0).to_bits()).collect()
    }

    /// The bytes a state of `vars` variables takes, at most (its values, their allocation,
    /// and the shared names' handle).
    pub const fn bytes(vars: usize) -> usize {
        std::mem::size_of::<State>() + crate::policy_parts::allocation(vars * 8)
    }
}

/// The bytes an allocation of `n` bytes takes from the allocator, at most (glibc's
/// malloc: 8 bytes of header, rounded up to 16, at least 32).
pub const fn allocation(n: usize) -> usize {
    if n == 0 {
        return 0;
    }
    let padded = (n + 8).div_ceil(16) * 16;
    if padded < 32 { 32 } else { padded }
}

impl PartialEq for State {
    fn eq(&self, other: &State) -> bool {
        self.names == other.names && self.bits() == other.bits()
    }
}

impl fmt::Debug for State {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_map().entries(self.names.iter().zip(self.values.iter())).finish()
    }
}

impl fmt::Display for State {
    /// `{"x": 3, "y": 4}`, as the document writes it.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match serde_json::to_string(self) {
            Ok(text) => f.write_str(&text),
            Err(_) => f.write_str("{}"),
        }
    }
}

impl Serialize for State {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(self.names.len()))?;
        for (name, &v) in self.names.iter().zip(self.values.iter()) {
            // Integral values as integers, as the document has always written them.
            if v.fract() == 0.0 && v.abs() < 9.0e15 {
                map.serialize_entry(name, &(v as i64))?;
            } else if v.is_finite() {
                map.serialize_entry(name, &v)?;
            } else {
                map.serialize_entry(name, &())?;
            }
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for State {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<State, D::Error> {
        struct StateVisitor;
        impl<'de> Visitor<'de> for StateVisitor {
            type Value = State;

            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a state, an object of numbers such as {\"x\": 3, \"y\": 4}")
            }

            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<State, A::Error> {
                let mut pairs: Vec<(String, f64)> = Vec::new();
                while let Some(name) = map.next_key::<String>()? {
                    if pairs.len() >= MAX_STATE_VARS {
                        return Err(de::Error::custom(format!(
                            "a state has more than {MAX_STATE_VARS} variables"
                        )));
                    }
                    let value: f64 = map.next_value()?;
                    pairs.push((name, value));
                }
                pairs.sort_by(|a, b| a.0.cmp(&b.0));
                if let Some(w) = pairs.windows(2).find(|w| w[0].0 == w[1].0) {
                    return Err(de::Error::custom(format!(
                        "a state names the variable `{}` twice",
                        w[0].0.escape_debug()
                    )));
                }
                let sorted: Vec<&str> = pairs.iter().map(|(n, _)| n.as_str()).collect();
                Ok(State {
                    names: shared_names(&sorted),
                    values: pairs.iter().map(|&(_, v)| v).collect(),
                })
            }
        }
        d.deserialize_map(StateVisitor)
    }
}

/// At most this many variables in one state of a document.
pub const MAX_STATE_VARS: usize = 64;

/// A Q-table in `policy.json`: its values, written as the 16 hex digits of each one's
/// IEEE-754 bits (so that they read back bit for bit, infinities and NaNs included).
#[derive(Clone, Debug, Default)]
pub struct HexTable(pub Vec<f64>);

impl PartialEq for HexTable {
    fn eq(&self, other: &HexTable) -> bool {
        self.0.len() == other.0.len()
            && self.0.iter().zip(&other.0).all(|(a, b)| a.to_bits() == b.to_bits())
    }
}

impl Eq for HexTable {}

impl Serialize for HexTable {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(self.0.len()))?;
        let mut buf = [0u8; 16];
        for v in &self.0 {
            seq.serialize_element(hex(v.to_bits(), &mut buf))?;
        }
        seq.end()
    }
}

/// `bits` as 16 lower-case hex digits.
fn hex(bits: u64, buf: &mut [u8; 16]) -> &str {
    const DIGITS: &[u8; 16] = b"0123456789abcdef";
    for (i, b) in buf.iter_mut().enumerate() {
        *b = DIGITS[((bits >> (60 - 4 * i)) & 0xf) as usize];
    }
    // Hex digits are ASCII.
    std::str::from_utf8(buf).unwrap_or("")
}

/// The value of 16 hex digits of its bits, or `None` for anything else (a sign, a
/// space, fewer or more digits).
pub fn unhex(text: &str) -> Option<f64> {
    if text.len() != 16 || !text.bytes().all(|b| b.is_ascii_hexdigit()) {
        return None;
    }
    u64::from_str_radix(text, 16).ok().map(f64::from_bits)
}

impl<'de> Deserialize<'de> for HexTable {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<HexTable, D::Error> {
        struct TableVisitor;
        impl<'de> Visitor<'de> for TableVisitor {
            type Value = HexTable;

            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a Q-table, a list of 16 hex digits per value")
            }

            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<HexTable, A::Error> {
                let mut values = Vec::new();
                while let Some(text) = seq.next_element::<HexDigits>()? {
                    values.push(text.0);
                }
                Ok(HexTable(values))
            }
        }
        d.deserialize_seq(TableVisitor)
    }
}

/// One Q-value as written: 16 hex digits.
struct HexDigits(f64);

impl<'de> Deserialize<'de> for HexDigits {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<HexDigits, D::Error> {
        struct DigitsVisitor;
        impl Visitor<'_> for DigitsVisitor {
            type Value = HexDigits;

            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("16 hex digits of an f64's bits")
            }

            fn visit_str<E: de::Error>(self, v: &str) -> Result<HexDigits, E> {
                unhex(v).map(HexDigits).ok_or_else(|| {
                    let shown: String = v.chars().take(24).collect();
                    E::custom(format!(
                        "a Q-table holds \"{}\", not 16 hex digits of an f64's bits",
                        shown.escape_debug()
                    ))
                })
            }
        }
        d.deserialize_str(DigitsVisitor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn states_read_back_to_the_same_values_and_share_their_names() {
        let vars = vec!["y".to_string(), "x".to_string()];
        let s = State::new(&vars, &[4.0, 2.5]);
        let text = serde_json::to_string(&s).expect("writes");
        assert_eq!(text, r#"{"x":2.5,"y":4}"#);
        let back: State = serde_json::from_str(&text).expect("reads");
        let again: State = serde_json::from_str(r#"{"y": 4, "x": 2.5}"#).expect("reads");
        assert_eq!(back, s);
        assert_eq!(again, s);
        assert!(Arc::ptr_eq(&back.names, &again.names), "one list of names");
        assert_eq!(back.get("y"), Some(4.0));
        assert_eq!(back.get("z"), None);
    }

    #[test]
    fn bad_states_and_q_values_are_refused_with_their_reason() {
        for (text, want) in [
            (r#"{"x": 1, "x": 2}"#, "names the variable `x` twice"),
            (r#"{"x": "1"}"#, "invalid type: string"),
            (r#"{"x": null}"#, "invalid type: null"),
        ] {
            let e = serde_json::from_str::<State>(text).expect_err(text).to_string();
            assert!(e.contains(want), "{text}: {e}");
        }
        for bad in
            ["+3ff000000000000", "3ff00000000000000", "3FF000000000000g", " 3ff0000000000000"]
        {
            let text = format!("[\"{bad}\"]");
            let e = serde_json::from_str::<HexTable>(&text).expect_err(bad).to_string();
            assert!(e.contains("not 16 hex digits"), "{bad}: {e}");
        }
        let t: HexTable =
            serde_json::from_str(r#"["3ff0000000000000", "fff0000000000000"]"#).expect("reads");
        assert_eq!(t.0, vec![1.0, f64::NEG_INFINITY]);
        assert_eq!(
            serde_json::to_string(&t).expect("writes"),
            r#"["3ff0000000000000","fff0000000000000"]"#
        );
    }
}
