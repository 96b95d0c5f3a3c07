//! Reading a learned function's `policy.json` in one pass: the weights (most of a large
//! document) straight into compact `(index, bits)` pairs, the rest as a document with its
//! values counted against a budget.

use super::*;
use hstl_runtime::digest::Digest;

/// A list of sparse entries as a document gives it (`None`: not a list), each `(index,
/// bits)`, or `None` where it is not `[INDEX, "16 hex digits"]`.
pub(super) type Entries = Option<Vec<Option<(u64, u64)>>>;

/// `weights.flat`: each option's name and entries, in the document's order.
pub(super) type FlatEntries = Vec<(String, Entries)>;

/// The learned weights as a document gives them.
#[derive(Clone, Debug, Default)]
pub(super) struct SparseWeights {
    pub(super) flat_len: Option<u64>,
    pub(super) options_len: Option<u64>,
    /// `None`: no `flat` object.
    pub(super) flat: Option<FlatEntries>,
    pub(super) options: Option<Entries>,
}

impl SparseWeights {
    pub(super) fn of_value(v: &Value) -> SparseWeights {
        let list = |v: &Value| v.as_array().map(|a| a.iter().map(entry).collect());
        SparseWeights {
            flat_len: v.get("flat_len").and_then(Value::as_u64),
            options_len: v.get("options_len").and_then(Value::as_u64),
            flat: v
                .get("flat")
                .and_then(Value::as_object)
                .map(|m| m.iter().map(|(k, e)| (k.clone(), list(e))).collect()),
            options: v.get("options").map(list),
        }
    }
}

/// The digest `policy.json`'s `checksum` holds for a learned function: FNV-1a over each
/// top-level entry but `checksum` and `weights` as compact JSON with its name, in name
/// order, then what `weights` feeds in ([`SparseWeights::digest`], or the writer's same
/// bytes from the weights themselves). A document reformatted reads back; one with a value
/// changed does not.
pub(super) fn digest(
    doc: &serde_json::Map<String, Value>,
    weights: impl FnOnce(&mut Digest),
) -> String {
    let mut d = Digest::new();
    for (key, value) in doc.iter().filter(|(k, _)| *k != "checksum" && *k != "weights") {
        d.bytes(key.as_bytes());
        // Writing into a digest cannot fail.
        let _ = serde_json::to_writer(&mut d, value);
    }
    weights(&mut d);
    d.hex()
}

/// One list of weight entries, each `(index, bits)` (`None`: an entry that is not one).
pub(super) type EntryIter<'a> = Box<dyn Iterator<Item = Option<(u64, u64)>> + 'a>;

/// The weights' part of [`digest`]: the two sizes, each option's entries in name order,
/// the options level's entries; an entry is its index and bits.
pub(super) fn digest_weights(
    d: &mut Digest,
    lens: (Option<u64>, Option<u64>),
    flat: Option<Vec<(&str, EntryIter<'_>)>>,
    options: Option<EntryIter<'_>>,
) {
    let entries = |d: &mut Digest, list: EntryIter<'_>| {
        for x in list {
            match x {
                Some((i, bits)) => {
                    d.bytes(&i.to_le_bytes());
                    d.bytes(&bits.to_le_bytes());
                }
                None => d.bytes(b"?"),
            }
        }
    };
    for len in [lens.0, lens.1] {
        d.bytes(&len.map_or([0xff; 8], u64::to_le_bytes));
    }
    if let Some(mut flat) = flat {
        flat.sort_by(|a, b| a.0.cmp(b.0));
        for (name, list) in flat {
            d.bytes(name.as_bytes());
            d.bytes(b"=");
            entries(d, list);
        }
    }
    if let Some(options) = options {
        d.bytes(b"options=");
        entries(d, options);
    }
}

/// The entries of one list as [`digest_weights`] reads them.
fn entry_list(e: &Entries) -> EntryIter<'_> {
    Box::new(e.iter().flatten().copied())
}

/// The nonzero weights of `v` as the document lists them, for [`digest_weights`].
pub(super) fn nonzero(v: &[f64]) -> EntryIter<'_> {
    Box::new(
        v.iter()
            .enumerate()
            .filter(|(_, x)| x.to_bits() != 0)
            .map(|(i, x)| Some((i as u64, x.to_bits()))),
    )
}

impl SparseWeights {
    /// Feeds the weights as the document gives them into [`digest`].
    pub(super) fn digest(&self, d: &mut Digest) {
        let flat = self
            .flat
            .as_ref()
            .map(|f| f.iter().map(|(n, e)| (n.as_str(), entry_list(e))).collect());
        let options = self.options.as_ref().map(entry_list);
        digest_weights(d, (self.flat_len, self.options_len), flat, options);
    }
}

/// `[INDEX, "16 hex digits"]` as `(index, bits)`.
fn entry(e: &Value) -> Option<(u64, u64)> {
    let pair = e.as_array().filter(|p| p.len() == 2)?;
    let h =
        pair[1].as_str().filter(|h| h.len() == 16 && h.bytes().all(|b| b.is_ascii_hexdigit()))?;
    Some((pair[0].as_u64()?, u64::from_str_radix(h, 16).ok()?))
}

/// The most JSON values (numbers, strings, lists, objects) that the entries of a learned
/// function's `policy.json` other than its weights may hold together: the world's 1,024
/// obstacles take about 6,000, so a document past this is no `policy.json` `hstlc train`
/// wrote, and is refused while it is read, before it takes memory.
pub const MAX_HEADER_VALUES: usize = 1 << 20;

/// The most options `weights.flat` may name (a spec has far fewer primitive options).
const MAX_FLAT_NAMES: usize = 1 << 16;

/// The most JSON values one weight entry `[INDEX, "16 hex digits"]` may hold (it holds 3).
const MAX_ENTRY_VALUES: usize = 8;

/// The top-level entries a learned function's `policy.json` has besides `weights`; any
/// other is skipped as it is read.
const HEADER_KEYS: [&str; 14] = [
    "checksum",
    "spec",
    "env",
    "state_vars",
    "actions",
    "options",
    "learner",
    "tiles",
    "memory",
    "switch",
    "steps",
    "choices",
    "spec_source",
    "seed",
];

/// Reads the top level of a `policy.json`: `weights` as [`SparseWeights`], the entries of
/// [`HEADER_KEYS`] kept within [`MAX_HEADER_VALUES`], any other skipped; a key given twice
/// is an error.
pub(super) struct TopLevel;

impl<'de> serde::de::Visitor<'de> for TopLevel {
    type Value = (Value, Option<SparseWeights>);
    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a JSON object")
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        let (mut doc, mut weights) = (serde_json::Map::new(), None);
        let left = std::cell::Cell::new(MAX_HEADER_VALUES);
        let mut seen: Vec<String> = Vec::new();
        while let Some(key) = map.next_key::<String>()? {
            if seen.contains(&key) {
                return Err(serde::de::Error::custom(format_args!(
                    "the entry `{}` is given twice",
                    crate::load::escape_controls(&key)
                )));
            }
            if key == "weights" {
                weights = Some(map.next_value_seed(WeightsSeed { left: &left })?);
            } else if HEADER_KEYS.contains(&key.as_str()) {
                let v = map.next_value_seed(Bounded { left: &left, what: "the document" })?;
                doc.insert(key.clone(), v);
            } else {
                map.next_value::<serde::de::IgnoredAny>()?;
                continue;
            }
            seen.push(key);
        }
        Ok((Value::Object(doc), weights))
    }
}

/// Reads one JSON value, counting it and everything in it against `left`: past the budget,
/// an error naming `what`, so that no part of a document takes more memory than its
/// budget allows, whatever it holds.
struct Bounded<'a> {
    left: &'a std::cell::Cell<usize>,
    what: &'static str,
}

impl Bounded<'_> {
    fn take<E: serde::de::Error>(&self) -> Result<(), E> {
        match self.left.get().checked_sub(1) {
            Some(left) => {
                self.left.set(left);
                Ok(())
            }
            None => Err(E::custom(format_args!(
                "{} holds more values than a policy.json `hstlc train` writes",
                self.what
            ))),
        }
    }
}

impl<'de> serde::de::DeserializeSeed<'de> for Bounded<'_> {
    type Value = Value;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> serde::de::Visitor<'de> for Bounded<'_> {
    type Value = Value;
    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E: serde::de::Error>(self, v: bool) -> Result<Value, E> {
        self.take()?;
        Ok(Value::Bool(v))
    }
    fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Value, E> {
        self.take()?;
        Ok(Value::from(v))
    }
    fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Value, E> {
        self.take()?;
        Ok(Value::from(v))
    }
    fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Value, E> {
        self.take()?;
        Ok(serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number))
    }
    fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Value, E> {
        self.take()?;
        Ok(Value::String(v.to_string()))
    }
    fn visit_string<E: serde::de::Error>(self, v: String) -> Result<Value, E> {
        self.take()?;
        Ok(Value::String(v))
    }
    fn visit_unit<E: serde::de::Error>(self) -> Result<Value, E> {
        self.take()?;
        Ok(Value::Null)
    }
    fn visit_none<E: serde::de::Error>(self) -> Result<Value, E> {
        self.visit_unit()
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        self.take()?;
        let mut out = Vec::new();
        while let Some(v) = seq.next_element_seed(Bounded { left: self.left, what: self.what })? {
            out.push(v);
        }
        Ok(Value::Array(out))
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        self.take()?;
        let mut out = serde_json::Map::new();
        while let Some(k) = map.next_key::<String>()? {
            self.take()?;
            let v = map.next_value_seed(Bounded { left: self.left, what: self.what })?;
            out.insert(k, v);
        }
        Ok(Value::Object(out))
    }
}

/// Reads `weights`: its lengths, and its lists entry by entry; anything but the lists counts
/// against `left`.
struct WeightsSeed<'a> {
    left: &'a std::cell::Cell<usize>,
}

impl<'de> serde::de::DeserializeSeed<'de> for WeightsSeed<'_> {
    type Value = SparseWeights;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<SparseWeights, D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> serde::de::Visitor<'de> for WeightsSeed<'_> {
    type Value = SparseWeights;
    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("the weights object")
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(
        self,
        mut map: A,
    ) -> Result<SparseWeights, A::Error> {
        let mut out = SparseWeights::default();
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "flat_len" => {
                    let v = map.next_value_seed(Bounded { left: self.left, what: "`weights`" })?;
                    out.flat_len = v.as_u64();
                }
                "options_len" => {
                    let v = map.next_value_seed(Bounded { left: self.left, what: "`weights`" })?;
                    out.options_len = v.as_u64();
                }
                "options" => out.options = Some(map.next_value_seed(EntriesSeed)?),
                "flat" => out.flat = map.next_value_seed(FlatSeed)?,
                _ => {
                    map.next_value::<serde::de::IgnoredAny>()?;
                }
            }
        }
        Ok(out)
    }
    // Anything else is no weights object: replay then says which field is missing.
    fn visit_seq<A: serde::de::SeqAccess<'de>>(
        self,
        mut seq: A,
    ) -> Result<SparseWeights, A::Error> {
        while seq.next_element::<serde::de::IgnoredAny>()?.is_some() {}
        Ok(SparseWeights::default())
    }
    fn visit_str<E>(self, _: &str) -> Result<SparseWeights, E> {
        Ok(SparseWeights::default())
    }
    fn visit_u64<E>(self, _: u64) -> Result<SparseWeights, E> {
        Ok(SparseWeights::default())
    }
    fn visit_i64<E>(self, _: i64) -> Result<SparseWeights, E> {
        Ok(SparseWeights::default())
    }
    fn visit_f64<E>(self, _: f64) -> Result<SparseWeights, E> {
        Ok(SparseWeights::default())
    }
    fn visit_bool<E>(self, _: bool) -> Result<SparseWeights, E> {
        Ok(SparseWeights::default())
    }
    fn visit_unit<E>(self) -> Result<SparseWeights, E> {
        Ok(SparseWeights::default())
    }
}

/// Reads `weights.flat`: option name to entries; `None` for anything but an object.
struct FlatSeed;

impl<'de> serde::de::DeserializeSeed<'de> for FlatSeed {
    type Value = Option<FlatEntries>;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        let v = d.deserialize_any(EntriesOrMap)?;
        Ok(match v {
            Lists::Map(m) => Some(m),
            _ => None,
        })
    }
}

/// Reads a list of entries; `None` for anything but a list.
struct EntriesSeed;

impl<'de> serde::de::DeserializeSeed<'de> for EntriesSeed {
    type Value = Entries;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        Ok(match d.deserialize_any(EntriesOrMap)? {
            Lists::List(l) => Some(l),
            _ => None,
        })
    }
}

/// A list of entries, a map of such lists, or something else.
enum Lists {
    List(Vec<Option<(u64, u64)>>),
    Map(FlatEntries),
    Other,
}

struct EntriesOrMap;

impl<'de> serde::de::Visitor<'de> for EntriesOrMap {
    type Value = Lists;
    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a list of weights")
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Lists, A::Error> {
        let mut out = Vec::new();
        // One small entry at a time: only its compact form stays, and an entry that holds
        // more than an entry does is refused as it is read.
        loop {
            let left = std::cell::Cell::new(MAX_ENTRY_VALUES);
            let seed = Bounded { left: &left, what: "an entry of `weights`" };
            let Some(e) = seq.next_element_seed(seed)? else { break };
            out.push(entry(&e));
        }
        Ok(Lists::List(out))
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Lists, A::Error> {
        let mut out = Vec::new();
        while let Some(key) = map.next_key::<String>()? {
            if out.len() == MAX_FLAT_NAMES {
                return Err(serde::de::Error::custom(format_args!(
                    "`weights.flat` names more than {MAX_FLAT_NAMES} options"
                )));
            }
            out.push((key, map.next_value_seed(EntriesSeed)?));
        }
        Ok(Lists::Map(out))
    }
    fn visit_str<E>(self, _: &str) -> Result<Lists, E> {
        Ok(Lists::Other)
    }
    fn visit_u64<E>(self, _: u64) -> Result<Lists, E> {
        Ok(Lists::Other)
    }
    fn visit_i64<E>(self, _: i64) -> Result<Lists, E> {
        Ok(Lists::Other)
    }
    fn visit_f64<E>(self, _: f64) -> Result<Lists, E> {
        Ok(Lists::Other)
    }
    fn visit_bool<E>(self, _: bool) -> Result<Lists, E> {
        Ok(Lists::Other)
    }
    fn visit_unit<E>(self) -> Result<Lists, E> {
        Ok(Lists::Other)
    }
}
