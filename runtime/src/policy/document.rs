//! The `policy.json` document as text: written indented down to the entries, each entry
//! on one line (`Shallow`), and read in one pass over its fields.

use super::*;

impl Policy {
    /// The document as JSON, indented down to the entries of its lists and maps; each
    /// entry (a policy row, a state, a Q-table) is written on one line.
    ///
    /// The last field, `checksum`, is a digest of the document's own fields as written
    /// ([`Policy::checksum`]): a reader refuses a document whose fields were changed after
    /// it was written.
    pub fn to_json(&self) -> Result<String, Error> {
        self.to_json_with(&[])
    }

    /// The digest `policy.json`'s `checksum` holds: FNV-1a (64 bits) over the document's
    /// own fields as [`Policy::to_json`] writes them without `checksum` and extra fields,
    /// as 16 hexadecimal digits. Computed by writing the document into the digest, never
    /// into memory.
    pub fn checksum(&self) -> Result<String, Error> {
        let mut digest = crate::digest::Digest::new();
        let mut ser = serde_json::Serializer::with_formatter(&mut digest, Shallow::default());
        self.serialize(&mut ser).map_err(|e| Error::Policy(e.to_string()))?;
        Ok(digest.hex())
    }

    /// The document as [`Policy::to_json`] writes it, with `extra` fields (such as the spec's
    /// source) after the document's own; an extra field may not reuse a document field's
    /// name.
    pub fn to_json_with(&self, extra: &[(&str, Value)]) -> Result<String, Error> {
        #[derive(Serialize)]
        struct WithExtra<'a> {
            #[serde(flatten)]
            policy: &'a Policy,
            #[serde(flatten)]
            extra: Map<String, Value>,
        }
        let mut fields = Map::new();
        for (name, value) in extra {
            if Policy::FIELDS.contains(name) || *name == CHECKSUM || fields.contains_key(*name) {
                return Err(Error::Policy(format!(
                    "the extra field {name} is already in the document; give it another name"
                )));
            }
            fields.insert((*name).to_string(), value.clone());
        }
        fields.insert(CHECKSUM.to_string(), Value::String(self.checksum()?));
        let mut out = Vec::new();
        let mut ser = serde_json::Serializer::with_formatter(&mut out, Shallow::default());
        WithExtra { policy: self, extra: fields }
            .serialize(&mut ser)
            .map_err(|e| Error::Policy(e.to_string()))?;
        String::from_utf8(out).map_err(|e| Error::Policy(e.to_string()))
    }

    /// Reads a document; the error says what is wrong and where.
    pub fn from_json(text: &str) -> Result<Policy, Error> {
        Policy::from_json_with(text, &[]).map(|(policy, _)| policy)
    }

    /// Reads a document and the `extra` fields among those beyond the document's own (as
    /// [`Policy::to_json_with`] writes them), in one typed pass: every field is read into
    /// its type as it comes, a field the document does not know and `extra` does not name
    /// is skipped without being kept, and a field given twice is an error. The error says
    /// what is wrong and where (line and column).
    pub fn from_json_with(
        text: &str,
        extra: &[&str],
    ) -> Result<(Policy, Map<String, Value>), Error> {
        let mut de = serde_json::Deserializer::from_str(text);
        let read = serde::Deserializer::deserialize_map(&mut de, DocumentVisitor { extra })
            .and_then(|doc| de.end().map(|()| doc));
        let (policy, extras, written) = read.map_err(|e| Error::Policy(e.to_string()))?;
        // A document written before checksums existed has none, and is read as it is.
        if let Some(written) = written {
            let own = policy.checksum()?;
            if own != written {
                return Err(Error::Policy(format!(
                    "the document was changed after it was written: its `checksum` is \
                     {written}, its fields give {own}; train again, or restore the file as \
                     it was written"
                )));
            }
        }
        Ok((policy, extras))
    }
}

/// The field that holds [`Policy::checksum`], written last.
const CHECKSUM: &str = "checksum";

/// The one pass over a document that [`Policy::from_json_with`] makes.
struct DocumentVisitor<'a> {
    extra: &'a [&'a str],
}

impl<'de> serde::de::Visitor<'de> for DocumentVisitor<'_> {
    /// The policy, the extra fields asked for, and the `checksum` when there is one.
    type Value = (Policy, Map<String, Value>, Option<String>);

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a policy.json document, an object")
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        use serde::de::{Error as _, IgnoredAny};
        fn set<T, E: serde::de::Error>(
            slot: &mut Option<T>,
            value: T,
            name: &str,
        ) -> Result<(), E> {
            if slot.is_some() {
                return Err(E::custom(format!("the field `{name}` is given twice")));
            }
            *slot = Some(value);
            Ok(())
        }
        let (mut spec, mut env, mut state_vars, mut actions, mut options) =
            (None, None, None, None, None);
        let (mut primitives, mut memory, mut options_policy, mut flat_policies) =
            (None, None, None, None);
        let (mut goals, mut max_steps, mut switch, mut q_tables) = (None, None, None, None);
        let mut checksum = None;
        let mut extras = Map::new();
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "spec" => set(&mut spec, map.next_value()?, &key)?,
                "env" => set(&mut env, map.next_value()?, &key)?,
                "state_vars" => set(&mut state_vars, map.next_value()?, &key)?,
                "actions" => set(&mut actions, map.next_value()?, &key)?,
                "options" => set(&mut options, map.next_value()?, &key)?,
                "primitives" => set(&mut primitives, map.next_value()?, &key)?,
                "memory" => set(&mut memory, map.next_value::<Option<MemoryDoc>>()?, &key)?,
                "goals" => set(&mut goals, map.next_value::<Option<Vec<String>>>()?, &key)?,
                "options_policy" => set(&mut options_policy, map.next_value()?, &key)?,
                "flat_policies" => set(&mut flat_policies, map.next_value()?, &key)?,
                "max_steps" => set(&mut max_steps, map.next_value()?, &key)?,
                "switch" => set(&mut switch, map.next_value()?, &key)?,
                "q_tables" => set(&mut q_tables, map.next_value()?, &key)?,
                CHECKSUM => set(&mut checksum, map.next_value::<String>()?, &key)?,
                k if self.extra.contains(&k) => {
                    if extras.contains_key(k) {
                        return Err(A::Error::custom(format!("the field `{k}` is given twice")));
                    }
                    let value: Value = map.next_value()?;
                    extras.insert(key, value);
                }
                _ => {
                    map.next_value::<IgnoredAny>()?;
                }
            }
        }
        let policy = Policy {
            spec: spec.ok_or_else(|| A::Error::missing_field("spec"))?,
            env: env.ok_or_else(|| A::Error::missing_field("env"))?,
            state_vars: state_vars.ok_or_else(|| A::Error::missing_field("state_vars"))?,
            actions: actions.ok_or_else(|| A::Error::missing_field("actions"))?,
            options: options.ok_or_else(|| A::Error::missing_field("options"))?,
            primitives: primitives.ok_or_else(|| A::Error::missing_field("primitives"))?,
            memory: memory.flatten(),
            goals: goals.flatten(),
            options_policy: options_policy
                .ok_or_else(|| A::Error::missing_field("options_policy"))?,
            flat_policies: flat_policies.ok_or_else(|| A::Error::missing_field("flat_policies"))?,
            max_steps: max_steps.ok_or_else(|| A::Error::missing_field("max_steps"))?,
            switch: switch.unwrap_or_default(),
            q_tables: q_tables.ok_or_else(|| A::Error::missing_field("q_tables"))?,
        };
        Ok((policy, extras, checksum))
    }
}

/// A JSON formatter that indents like `serde_json`'s pretty printer down to depth 2 and
/// writes anything deeper on one line, with a space after each `,` and `:`.
#[derive(Default)]
struct Shallow {
    depth: usize,
    has_value: bool,
}

impl Shallow {
    const INDENTED: usize = 2;

    fn open<W: ?Sized + std::io::Write>(&mut self, w: &mut W, c: &[u8]) -> std::io::Result<()> {
        self.depth += 1;
        self.has_value = false;
        w.write_all(c)
    }

    fn close<W: ?Sized + std::io::Write>(&mut self, w: &mut W, c: &[u8]) -> std::io::Result<()> {
        self.depth -= 1;
        if self.has_value && self.depth < Self::INDENTED {
            self.newline(w)?;
        }
        w.write_all(c)
    }

    fn item<W: ?Sized + std::io::Write>(&mut self, w: &mut W, first: bool) -> std::io::Result<()> {
        if self.depth <= Self::INDENTED {
            w.write_all(if first { b"" } else { b"," })?;
            self.newline(w)
        } else {
            w.write_all(if first { b"" } else { b", " })
        }
    }

    fn newline<W: ?Sized + std::io::Write>(&self, w: &mut W) -> std::io::Result<()> {
        w.write_all(b"\n")?;
        for _ in 0..self.depth {
            w.write_all(b"  ")?;
        }
        Ok(())
    }
}

impl serde_json::ser::Formatter for Shallow {
    fn begin_array<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        self.open(w, b"[")
    }

    fn end_array<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        self.close(w, b"]")
    }

    fn begin_array_value<W: ?Sized + std::io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> std::io::Result<()> {
        self.item(w, first)
    }

    fn end_array_value<W: ?Sized + std::io::Write>(&mut self, _: &mut W) -> std::io::Result<()> {
        self.has_value = true;
        Ok(())
    }

    fn begin_object<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        self.open(w, b"{")
    }

    fn end_object<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        self.close(w, b"}")
    }

    fn begin_object_key<W: ?Sized + std::io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> std::io::Result<()> {
        self.item(w, first)
    }

    fn begin_object_value<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        w.write_all(b": ")
    }

    fn end_object_value<W: ?Sized + std::io::Write>(&mut self, _: &mut W) -> std::io::Result<()> {
        self.has_value = true;
        Ok(())
    }
}
