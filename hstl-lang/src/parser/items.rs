//! The item splitter: a balanced-delimiter scan of the tokens into spec headers and items.

use super::*;

pub(super) const ITEM_KEYWORDS: [&str; 6] = ["let", "task", "option", "state", "learn", "spec"];

pub(super) struct Splitter<'a, 'd> {
    pub(super) src: &'a str,
    pub(super) deep_comments: Vec<Range<usize>>,
    /// Where each unterminated string starts, in source order (already reported).
    pub(super) open_strings: Vec<usize>,
    pub(super) toks: &'a [Tok],
    pub(super) ends: &'a [usize],
    pub(super) i: usize,
    /// Whether large specs are parsed on several threads.
    pub(super) parallel: bool,
    pub(super) diagnostics: &'d mut Vec<Diagnostic>,
}

impl Splitter<'_, '_> {
    pub(super) fn text(&self, k: usize) -> &str {
        let t = self.toks[k];
        &self.src[t.start..t.end]
    }

    pub(super) fn is(&self, k: usize, s: &str) -> bool {
        k < self.toks.len() && self.text(k) == s
    }

    /// Parses one spec starting at `self.i`, or skips junk up to the next `spec`.
    pub(super) fn spec(&mut self) -> Option<Spec> {
        let start = self.i;
        let mut k = start;
        while k < self.toks.len() && self.toks[k].kind == TokKind::Doc {
            k += 1;
        }
        if !self.is(k, "spec") {
            // Junk at the top level: report it once and skip to the next spec.
            let bad = if k < self.toks.len() { k } else { start };
            let t = self.toks[bad];
            let (range, found) = if k < self.toks.len() {
                (t.start..t.end, format!("`{}`", self.text(bad)))
            } else {
                (t.end..t.end, "end of file".to_string())
            };
            let help = if found == "`;`" {
                "remove this `;`: a spec ends at its `}`"
            } else {
                "a file holds specs: `spec Name { ... }`"
            };
            self.diagnostics.push(
                Diagnostic::new("HSTL001", range, format!("expected `spec`, found {found}"))
                    .with_help(help),
            );
            self.i = k + 1;
            while self.i < self.toks.len() && !self.is(self.i, "spec") {
                self.i += 1;
            }
            // Docs in front of the next spec belong to it.
            while self.i > k + 1 && self.toks[self.i - 1].kind == TokKind::Doc {
                self.i -= 1;
            }
            return None;
        }
        let spec_kw = k;
        // Header: docs, `spec`, a name and `{`.
        let mut h = spec_kw + 1;
        while h < self.toks.len() && h < spec_kw + 3 && !self.is(h, "{") {
            h += 1;
        }
        let has_brace = self.is(h, "{");
        let header_end = if has_brace { h + 1 } else { h.min(self.toks.len()) };
        let head_range = self.toks[start].start..self.toks[header_end - 1].end;
        let mut doc = None;
        let mut name =
            Ident { name: String::new(), range: self.toks[spec_kw].start..self.toks[spec_kw].end };
        let head = if self.has_deep_comment(&head_range) {
            Err(None)
        } else {
            parse_detailed(Rule::spec_head, &self.src[head_range.clone()]).map_err(Some)
        };
        match head {
            Ok(mut pairs) => {
                let mut docs = Vec::new();
                if let Some(head) = pairs.next() {
                    for p in head.into_inner() {
                        match p.as_rule() {
                            Rule::doc => docs.push(p),
                            Rule::ident => name = ident(&p, head_range.start),
                            _ => {}
                        }
                    }
                }
                doc = make_doc(docs, head_range.start);
            }
            Err(None) => {}
            Err(Some(e)) => {
                self.diagnostics.push(self.syntax_error(&e, head_range.clone()));
            }
        }
        self.i = header_end;
        let mut items = Vec::new();
        let mut broken = Vec::new();
        let mut end = head_range.end;
        if !has_brace {
            // Without a body there is nothing more to read in this spec.
            return Some(Spec {
                doc,
                name,
                items,
                broken: Vec::new(),
                range: head_range.start..end,
            });
        }
        let mut bounds = Vec::new();
        let mut unclosed = None;
        loop {
            if self.i >= self.toks.len() {
                let at = self.src.len();
                unclosed = Some(
                    Diagnostic::new("HSTL001", at..at, "expected `}`, found end of file")
                        .with_label(self.toks[h].start..self.toks[h].end, "this `{` is not closed")
                        .with_help("close the spec with `}`"),
                );
                end = at;
                break;
            }
            if self.is(self.i, "}") {
                end = self.toks[self.i].end;
                self.i += 1;
                break;
            }
            if self.is(self.i, "spec") {
                let t = self.toks[self.i];
                unclosed = Some(
                    Diagnostic::new("HSTL001", t.start..t.end, "expected `}`, found `spec`")
                        .with_label(self.toks[h].start..self.toks[h].end, "this `{` is not closed")
                        .with_help("close the previous spec with `}` before starting another"),
                );
                end = self.toks[self.i - 1].end;
                break;
            }
            let (a, b) = self.item_bounds();
            self.i = b;
            bounds.push((a, b));
        }
        // Items are independent once split: parse them, then report in source order.
        for ((a, b), (item, mut diags)) in bounds.iter().zip(self.items(&bounds)) {
            self.diagnostics.append(&mut diags);
            match item {
                Some(item) => items.push(item),
                None => broken.push(self.broken(*a, *b)),
            }
        }
        self.diagnostics.extend(unclosed);
        Some(Spec { doc, name, items, broken, range: head_range.start..end })
    }

    /// Finds the tokens `[a, b)` of the item starting at `self.i`.
    pub(super) fn item_bounds(&mut self) -> (usize, usize) {
        let a = self.i;
        let mut k = a;
        let mut depth = 0usize;
        let mut brace_depth = 0usize;
        let mut seen_non_doc = false;
        while k < self.toks.len() {
            let t = self.toks[k];
            let s = self.text(k);
            if seen_non_doc && k > a {
                let starts_item = (t.kind == TokKind::Word && ITEM_KEYWORDS.contains(&s))
                    || (s == "options" && brace_depth == 0)
                    || (s == "world"
                        && self.toks.get(k + 1).is_some_and(|n| n.kind == TokKind::Str))
                    || (t.kind == TokKind::Doc && depth == 0);
                if starts_item {
                    break;
                }
            }
            if depth == 0 && s == "}" {
                break;
            }
            if t.kind != TokKind::Doc {
                seen_non_doc = true;
            }
            k += 1;
            match s {
                "(" | "[" | "{" => {
                    depth += 1;
                    brace_depth += usize::from(s == "{");
                }
                ")" | "]" | "}" => {
                    depth = depth.saturating_sub(1);
                    if s == "}" {
                        brace_depth = brace_depth.saturating_sub(1);
                        if depth == 0 {
                            break;
                        }
                    }
                }
                ";" if depth == 0 => break,
                _ => {}
            }
        }
        (a, k.max(a + 1).min(self.toks.len()))
    }

    /// What a broken item seems to declare, from its tokens.
    pub(super) fn broken(&self, a: usize, b: usize) -> BrokenItem {
        let mut k = a;
        while k < b && self.toks[k].kind == TokKind::Doc {
            k += 1;
        }
        let keyword =
            (k < b && self.toks[k].kind == TokKind::Word).then(|| self.text(k).to_string());
        let mut names = Vec::new();
        match keyword.as_deref() {
            Some("let" | "option") if k + 1 < b && self.toks[k + 1].kind == TokKind::Word => {
                names.push(self.text(k + 1).to_string());
            }
            Some("state") => {
                for j in k + 1..b.saturating_sub(1) {
                    if self.toks[j].kind == TokKind::Word && self.is(j + 1, ":") {
                        names.push(self.text(j).to_string());
                    }
                }
            }
            _ => {}
        }
        BrokenItem { keyword, names, range: self.toks[a].start..self.toks[b - 1].end }
    }

    /// Whether a block comment nested too deeply for pest lies inside `range` (it was
    /// reported by the lexer).
    pub(super) fn has_deep_comment(&self, range: &Range<usize>) -> bool {
        // The comments are in source order and do not overlap.
        let k = self.deep_comments.partition_point(|c| c.end <= range.start);
        self.deep_comments.get(k).is_some_and(|c| c.start < range.end)
    }

    /// Whether a string that the lexer found unterminated (and reported) lies inside `range`.
    pub(super) fn has_open_string(&self, range: &Range<usize>) -> bool {
        let k = self.open_strings.partition_point(|&s| s < range.start);
        self.open_strings.get(k).is_some_and(|&s| s < range.end)
    }

    /// Parses the items of `bounds` (token ranges), on several threads when there are
    /// many; each result comes with the item's diagnostics, in the order of `bounds`.
    pub(super) fn items(&self, bounds: &[(usize, usize)]) -> Vec<ItemResult> {
        let serial = || bounds.iter().map(|&(a, b)| self.item(a, b)).collect();
        // Asking for the core count reads files, so small inputs never ask.
        if !self.parallel || bounds.len() < PARALLEL_ITEMS {
            return serial();
        }
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(MAX_THREADS);
        if threads < 2 {
            return serial();
        }
        let chunk = bounds.len().div_ceil(threads);
        let run = |part: &[(usize, usize)]| -> Vec<ItemResult> {
            part.iter().map(|&(a, b)| self.item(a, b)).collect()
        };
        std::thread::scope(|scope| {
            let mut parts = bounds.chunks(chunk);
            let first = parts.next().unwrap_or(&[]);
            let handles: Vec<_> = parts
                .map(|part| {
                    let spawned =
                        std::thread::Builder::new().spawn_scoped(scope, move || run(part));
                    (part, spawned)
                })
                .collect();
            let mut out = run(first);
            for (part, spawned) in handles {
                // A thread that could not start (or failed) leaves its part to this one.
                match spawned.ok().and_then(|h| h.join().ok()) {
                    Some(results) => out.extend(results),
                    None => out.extend(run(part)),
                }
            }
            out
        })
    }

    /// Parses the item of tokens `[a, b)`: the item, or `None` if it is broken, and its
    /// diagnostics.
    pub(super) fn item(&self, a: usize, b: usize) -> ItemResult {
        let mut diagnostics = Vec::new();
        let item = self.item_into(a, b, &mut diagnostics);
        (item, diagnostics)
    }

    pub(super) fn item_into(
        &self,
        a: usize,
        b: usize,
        diagnostics: &mut Vec<Diagnostic>,
    ) -> Option<Item> {
        let range = self.toks[a].start..self.toks[b - 1].end;
        if self.has_deep_comment(&range) || self.has_open_string(&range) {
            return None;
        }
        // Bracket nesting is checked before pest so that deep input cannot exhaust the stack.
        let mut depth = 0usize;
        for k in a..b {
            match self.text(k) {
                "(" | "[" | "{" => {
                    depth += 1;
                    if depth > MAX_NESTING {
                        let t = self.toks[k];
                        diagnostics.push(Diagnostic::new(
                            "HSTL001",
                            t.start..t.end,
                            format!("brackets nested too deeply (more than {MAX_NESTING} levels)"),
                        ));
                        return None;
                    }
                }
                ")" | "]" | "}" => depth = depth.saturating_sub(1),
                _ => {}
            }
        }
        let mut fb =
            Builder { offset: range.start, ends: &self.ends[a..b], diagnostics: Vec::new() };
        let mut fast = Fast { src: self.src, toks: &self.toks[a..b], b: &mut fb };
        if let Some(item) = fast.let_item()
            && fb.diagnostics.is_empty()
        {
            return Some(item);
        }
        let text = &self.src[range.clone()];
        match parse_detailed(Rule::item_entry, text) {
            Ok(mut pairs) => {
                let entry = pairs.next()?;
                let inner = entry.into_inner().find(|p| p.as_rule() != Rule::EOI)?;
                let mut b = Builder {
                    offset: range.start,
                    ends: &self.ends[a..b],
                    diagnostics: Vec::new(),
                };
                match b.item(inner) {
                    Ok(item) => {
                        diagnostics.append(&mut b.diagnostics);
                        Some(item)
                    }
                    Err(Fail(d)) => {
                        diagnostics.push(d);
                        None
                    }
                }
            }
            Err(e) => {
                diagnostics.push(self.syntax_error(&e, range));
                None
            }
        }
    }

    /// Turns a pest error on the text `piece` into an HSTL001 with readable expectations.
    pub(super) fn syntax_error(
        &self,
        e: &pest::error::Error<Rule>,
        piece: Range<usize>,
    ) -> Diagnostic {
        let loc = match e.location {
            pest::error::InputLocation::Pos(p) => p,
            pest::error::InputLocation::Span((s, _)) => s,
        };
        let attempts = e.parse_attempts();
        let far = attempts.as_ref().map_or(loc, |a| a.max_position.max(loc));
        let pos = piece.start + far;
        let mut expected: Vec<String> = Vec::new();
        if let Some(attempts) = &attempts {
            // `ParsingToken` is not exported; its display is the literal for exact tokens.
            let tokens: Vec<String> =
                attempts.expected_tokens().iter().map(ToString::to_string).collect();
            expected.extend(describe_tokens(tokens));
        }
        if expected.is_empty()
            && far == loc
            && let pest::error::ErrorVariant::ParsingError { positives, .. } = &e.variant
        {
            expected.extend(positives.iter().filter_map(|r| rule_words(*r)).map(String::from));
        }
        let mut seen = std::collections::BTreeSet::new();
        expected.retain(|w| seen.insert(w.clone()));
        expected.sort_by_key(|w| (w.starts_with('`'), w.clone()));
        let what = match expected.len() {
            0 => "something else".to_string(),
            1 => expected[0].clone(),
            n => format!("{} or {}", expected[..n - 1].join(", "), expected[n - 1]),
        };
        // What was found: the next token in the whole file after the error position.
        // The tokens are in source order: a binary search keeps many errors linear.
        let k = self.toks.partition_point(|t| t.start < pos);
        let next = self.toks.get(k);
        let (range, found) = match next {
            Some(t) if t.start < piece.end => {
                (t.start..t.end, format!("`{}`", &self.src[t.start..t.end]))
            }
            Some(t) => (pos..pos, format!("`{}`", &self.src[t.start..t.end])),
            None => (pos..pos, "end of file".to_string()),
        };
        let limit = matches!(&e.variant,
            pest::error::ErrorVariant::CustomError { message } if message.contains("limit reached"));
        let message = if limit {
            "input too deeply nested to parse".to_string()
        } else {
            format!("expected {what}, found {found}")
        };
        let d = Diagnostic::new("HSTL001", range, message);
        match self.hint(k, &expected, &piece) {
            Some(help) if !limit => d.with_help(help),
            _ => d,
        }
    }

    /// Help for a syntax error found at token `k` (`expected` in words): a misspelt
    /// keyword, an interval written with a comma, a `;` too many.
    pub(super) fn hint(
        &self,
        k: usize,
        expected: &[String],
        piece: &Range<usize>,
    ) -> Option<String> {
        let text = |j: usize| self.toks.get(j).map(|t| &self.src[t.start..t.end]);
        let found = text(k)?;
        let expects = |w: &str| expected.iter().any(|e| e == w);
        if found == ";" && expects("`let`") {
            return Some("remove this `;`: an item ends with its own".into());
        }
        if found == "[" {
            let before = text(k.wrapping_sub(1));
            if before == Some("prev") {
                return Some(
                    "`prev` takes no interval: it looks one step back; for a window write \
                     `once[a..=b] f` or `historically[a..=b] f`"
                        .into(),
                );
            }
            if before == Some("next") {
                return Some(
                    "`next` takes no interval: it looks one step ahead; for a window write \
                     `eventually[a..=b] f` or `always[a..=b] f`"
                        .into(),
                );
            }
        }
        if found == "," && expects("`..`") {
            let number =
                |j: usize| self.toks.get(j).filter(|t| t.kind == TokKind::Number).map(|_| text(j));
            let (a, b) = (number(k.wrapping_sub(1)).flatten()?, number(k + 1).flatten()?);
            return Some(format!(
                "an interval is a Rust range: `[{a}..={b}]` holds the steps {a} to {b}, \
                 `[{a}..{b}]` leaves out {b}"
            ));
        }
        if found == ":" && expects("`..`") {
            let number =
                |j: usize| self.toks.get(j).filter(|t| t.kind == TokKind::Number).map(|_| text(j));
            let (a, b) = (number(k.wrapping_sub(1)).flatten()?, number(k + 1).flatten()?);
            return Some(format!(
                "rtamt writes `[{a}:{b}]`; hstl writes `[{a}..={b}]` (the steps {a} to {b}), or \
                 `[{a}..{b}]` to leave out {b}"
            ));
        }
        // rtamt's and the textbooks' spellings, here or just before the error.
        for j in [k, k.wrapping_sub(1)] {
            let hint = match text(j) {
                Some("and" | "&" | "AND") => "write `&&` for and",
                Some("or" | "|" | "OR") => "write `||` for or",
                Some("not" | "NOT" | "~") => "write `!` for not",
                Some("implies" | "=>") => "write `->` for implies",
                Some("G") => "write `always` for G (□): `always[0..=10] f`",
                Some("F") => "write `eventually` for F (◇): `eventually[0..=10] f`",
                Some("U") => "write `until` for U: `f until[0..=10] g`",
                Some("H") => "write `historically` for H: `historically[0..=10] f`",
                Some("O") => "write `once` for O: `once[0..=10] f`",
                Some("S") => "write `since` for S: `f since[0..=10] g`",
                _ => continue,
            };
            return Some(hint.into());
        }
        // A word just before the error, or at it, that is a keyword misspelt.
        for j in [k.wrapping_sub(1), k] {
            let Some(t) = self.toks.get(j).filter(|t| t.kind == TokKind::Word) else { continue };
            if t.start < piece.start || KEYWORDS.contains(&&self.src[t.start..t.end]) {
                continue;
            }
            let word = &self.src[t.start..t.end];
            if let Some(kw) =
                crate::suggest::closest(word, KEYWORDS.iter().copied(), &mut u64::MAX.clone())
            {
                return Some(format!("did you mean `{kw}`?"));
            }
        }
        None
    }
}
