//! Re-parsing after an edit: only the items around the change are parsed again.
//!
//! An editor sends the whole text after every keystroke. [`reparse`] takes the previous
//! [`Parsed`] (moved in, nothing is copied), finds the changed bytes, and re-parses only
//! the items of one spec body around them (one more item on each side, so that item
//! boundaries that depend on the next token stay right; more before it when the edit
//! touches the first token of that item). The items before are kept as
//! they are; the items after are kept with their byte ranges shifted. The result is
//! exactly what [`parse`] gives for the new text (same tree, same diagnostics, up to
//! their order); [`crate::check_parsed`] then checks it without parsing again.
//!
//! Whenever the change is not confined to the inside of one spec body — it touches a
//! spec header or a closing brace, leaves brackets unbalanced, opens a comment that runs
//! on, adds a `spec`, or the previous parse had errors outside its items — the whole
//! text is parsed again instead. The test `tests/incremental.rs` holds the result
//! against [`parse`] on random edits.

use std::ops::Range;

use crate::diagnostic::Diagnostic;
use crate::format::lex;
use crate::parser::TokKind as Kind;
use crate::parser::{Parsed, parse};
use crate::syntax::*;

/// What [`reparse`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reuse {
    /// The whole text was parsed again.
    Full,
    /// Only this many bytes of the new text were parsed again.
    Partial(usize),
}

/// The text of `new` parsed, reusing `prev`, the parse of `old`. Equal to `parse(new)`
/// (diagnostics possibly in another order).
pub fn reparse(prev: Parsed, old: &str, new: &str) -> (Parsed, Reuse) {
    match Plan::new(&prev, old, new) {
        Some(plan) => plan.apply(prev),
        None => (parse(new), Reuse::Full),
    }
}

/// The wrapper around a re-parsed stretch of a spec body.
const HEAD: &str = "spec __Reparsed {\n";
const TAIL: &str = "\n}";

/// Where the re-parsed stretch lies, in old and new coordinates.
struct Plan {
    /// Index of the spec whose body changed.
    spec: usize,
    /// Pieces (items and broken items, in source order) kept before the stretch.
    keep_before: usize,
    /// Index of the first piece kept after the stretch.
    keep_after: usize,
    /// The stretch in the old text.
    old_mid: Range<usize>,
    /// The stretch in the new text.
    new_mid: Range<usize>,
    /// The parse of `HEAD + stretch + TAIL`.
    wrapped: Parsed,
    /// What becomes of each previous diagnostic.
    fates: Vec<Fate>,
}

/// What becomes of a previous diagnostic.
#[derive(Clone, Copy)]
enum Fate {
    /// Before the stretch: kept as it is.
    Keep,
    /// After the stretch: kept, shifted.
    Shift,
    /// In the stretch: replaced by the new parse of it.
    Drop,
}

/// A piece of a spec body: an item or a broken item.
#[derive(Clone, Copy)]
enum Piece {
    Item(usize),
    Broken(usize),
}

fn pieces(spec: &Spec) -> Vec<(Range<usize>, Piece)> {
    let mut v: Vec<(Range<usize>, Piece)> = spec
        .items
        .iter()
        .enumerate()
        .map(|(i, it)| (it.range(), Piece::Item(i)))
        .chain(spec.broken.iter().enumerate().map(|(i, b)| (b.range.clone(), Piece::Broken(i))))
        .collect();
    v.sort_by_key(|p| p.0.start);
    v
}

/// The end of the `{` that opens the body of `spec` (its header parsed).
fn body_start(src: &str, spec: &Spec) -> Option<usize> {
    // Only comments can stand between the name and `{`: a short window suffices (a
    // longer comment there makes the caller parse everything again).
    let mut end = spec.range.end.min(spec.name.range.end + 4096);
    while !src.is_char_boundary(end) {
        end -= 1;
    }
    let toks = lex(src.get(spec.name.range.end..end)?);
    let open = toks.iter().find(|t| !t.is_comment())?;
    let at = spec.name.range.end + open.start;
    (src.get(at..at + 1) == Some("{")).then_some(at + 1)
}

impl Plan {
    fn new(prev: &Parsed, old: &str, new: &str) -> Option<Plan> {
        // The changed bytes: [cs, old_end) in the old text, [cs, new_end) in the new.
        let (a, b) = (old.as_bytes(), new.as_bytes());
        let mut cs = a.iter().zip(b).take_while(|(x, y)| x == y).count();
        let max_suffix = a.len().min(b.len()) - cs;
        let suffix =
            a.iter().rev().zip(b.iter().rev()).take(max_suffix).take_while(|(x, y)| x == y).count();
        while !new.is_char_boundary(cs) || !old.is_char_boundary(cs) {
            cs -= 1;
        }
        let old_end = a.len() - suffix;
        if old == new {
            return None;
        }
        // The one spec whose body holds the change.
        let spec_i =
            prev.file.specs.iter().position(|s| s.range.start <= cs && old_end < s.range.end)?;
        let spec = &prev.file.specs[spec_i];
        if spec.name.name.is_empty() || !old[..spec.range.end].ends_with('}') {
            return None;
        }
        let body = body_start(old, spec)?;
        let close = spec.range.end - 1;
        if cs < body || old_end > close {
            return None;
        }
        // The closing brace is a token, not the end of a comment that runs to the end of
        // the file (`spec S { // }` has no closing brace).
        let comments = &prev.file.comments;
        let k = comments.partition_point(|c| c.range.end <= close);
        if comments.get(k).is_some_and(|c| c.range.start <= close) {
            return None;
        }
        let pieces = pieces(spec);
        // The closing brace is the spec's own (not the end of an item of a spec that
        // runs to the end of the file).
        if pieces.last().is_some_and(|p| p.0.end > close) {
            return None;
        }
        // Keep the pieces before the change but the last of them; the items after it but
        // the first.
        let before = pieces.iter().take_while(|p| p.0.end <= cs).count();
        let mut keep_before = before.saturating_sub(1);
        // A kept piece ends where it does because of the token after it (an item
        // keyword, a doc comment, `}`), the first of the stretch: the edit must leave that
        // token whole (deleting the space in `let let` makes it `letlet`, no keyword, and
        // the piece before runs on), else the stretch starts one piece earlier.
        while keep_before > 0 && !first_token_untouched(old, pieces[keep_before - 1].0.end, cs) {
            keep_before -= 1;
        }
        let first_after = pieces.iter().position(|p| p.0.start >= old_end).unwrap_or(pieces.len());
        let keep_after = (first_after + 1).min(pieces.len());
        let mid_start = if keep_before > 0 { pieces[keep_before - 1].0.end } else { body };
        let mid_end_old = pieces.get(keep_after).map_or(close, |p| p.0.start);
        if mid_start > cs || mid_end_old < old_end {
            return None;
        }
        let delta = new.len() as isize - old.len() as isize;
        let mid_end_new = (mid_end_old as isize + delta) as usize;
        // Each old diagnostic belongs to a kept piece (kept, or shifted after the
        // stretch), to the stretch (dropped), or to text outside this spec body.
        let kept_before = &pieces[..keep_before];
        let kept_after = &pieces[keep_after..];
        let within = |ps: &[(Range<usize>, Piece)], r: &Range<usize>| {
            let k = ps.partition_point(|p| p.0.end < r.end);
            ps.get(k).is_some_and(|p| p.0.start <= r.start && r.end <= p.0.end)
        };
        let mut fates = Vec::with_capacity(prev.diagnostics.len());
        for d in &prev.diagnostics {
            let fate = if within(kept_before, &d.range) {
                Fate::Keep
            } else if within(kept_after, &d.range) {
                Fate::Shift
            } else if mid_start <= d.range.start && d.range.end <= mid_end_old {
                if d.labels.iter().any(|l| l.range.start < mid_start || l.range.end > mid_end_old) {
                    return None;
                }
                Fate::Drop
            } else if d.range.end <= spec.range.start && d.range.start < spec.range.start {
                Fate::Keep
            } else if d.range.start >= spec.range.end {
                Fate::Shift
            } else {
                return None;
            };
            let into_stretch = |r: &Range<usize>| r.end > mid_start && r.start < mid_end_old;
            if !matches!(fate, Fate::Drop) && d.labels.iter().any(|l| into_stretch(&l.range)) {
                return None;
            }
            fates.push(fate);
        }
        let mid = new.get(mid_start..mid_end_new)?;
        // A string runs to its closing quote or the line's end, which may lie in a kept
        // piece; strings are rare (a `world` item), so a stretch with one parses whole.
        if !stretch_is_closed(mid) || mid.contains('"') {
            return None;
        }
        // A syntax error names the token after it, which for the last item of the
        // stretch is the first token after the stretch: it goes into the wrapper too, and
        // what it parses into is dropped.
        let next = match pieces.get(keep_after) {
            Some(_) => {
                let rest = &new[mid_end_new..];
                let line = &rest[..rest.find('\n').unwrap_or(rest.len())];
                let t = lex(line).into_iter().find(|t| !t.is_comment())?;
                &line[t.start..t.end]
            }
            None => "",
        };
        let text = format!("{HEAD}{mid}\n{next}{TAIL}");
        let mut wrapped = parse(&text);
        let inner = HEAD.len()..HEAD.len() + mid.len();
        wrapped.diagnostics.retain(|d| d.range.start < inner.end);
        wrapped.file.comments.retain(|c| c.range.start < inner.end);
        if let Some(w) = wrapped.file.specs.first_mut() {
            w.items.retain(|i| i.range().start < inner.end);
            w.broken.retain(|b| b.range.start < inner.end);
        }
        // The last piece of the stretch must end inside it, before the token of the kept
        // piece after it (a `state` item broken by a line comment that the edit extends
        // runs on over a next piece that starts with no keyword), so that the kept piece
        // starts where it did.
        let inside = |w: &Spec| {
            w.items.iter().all(|i| i.range().end <= inner.end)
                && w.broken.iter().all(|b| b.range.end <= inner.end)
        };
        let ok = wrapped.file.specs.len() == 1
            && wrapped.file.specs[0].range.end == text.len()
            && inside(&wrapped.file.specs[0])
            && wrapped.diagnostics.iter().all(|d| {
                inner.start <= d.range.start
                    && d.range.end <= inner.end
                    && d.labels
                        .iter()
                        .all(|l| inner.start <= l.range.start && l.range.end <= inner.end)
            });
        if !ok {
            return None;
        }
        Some(Plan {
            spec: spec_i,
            keep_before,
            keep_after,
            old_mid: mid_start..mid_end_old,
            new_mid: mid_start..mid_end_new,
            wrapped,
            fates,
        })
    }

    fn apply(self, prev: Parsed) -> (Parsed, Reuse) {
        let delta = self.new_mid.end as isize - self.old_mid.end as isize;
        let from_wrapped = self.new_mid.start as isize - HEAD.len() as isize;
        let Parsed { file, diagnostics } = prev;
        let File { specs, comments } = file;
        let mut out_specs = Vec::with_capacity(specs.len());
        let mut wrapped_spec = self.wrapped.file.specs.into_iter().next();
        for (i, mut spec) in specs.into_iter().enumerate() {
            if i < self.spec {
                out_specs.push(spec);
                continue;
            }
            if i > self.spec {
                shift_spec(&mut spec, delta);
                out_specs.push(spec);
                continue;
            }
            let order = pieces(&spec);
            let keep: Vec<(bool, Piece)> = order
                .iter()
                .enumerate()
                .filter(|(k, _)| *k < self.keep_before || *k >= self.keep_after)
                .map(|(k, p)| (k >= self.keep_after, p.1))
                .collect();
            let mut old_items: Vec<Option<Item>> = spec.items.drain(..).map(Some).collect();
            let mut old_broken: Vec<Option<BrokenItem>> = spec.broken.drain(..).map(Some).collect();
            let (mut items, mut broken) = (Vec::new(), Vec::new());
            let mut mid_items = Vec::new();
            let mut mid_broken = Vec::new();
            if let Some(w) = wrapped_spec.take() {
                mid_items = w.items;
                mid_broken = w.broken;
            }
            let mut mid_done = false;
            for (after, piece) in keep {
                if after && !mid_done {
                    mid_done = true;
                    push_mid(
                        &mut items,
                        &mut broken,
                        &mut mid_items,
                        &mut mid_broken,
                        from_wrapped,
                    );
                }
                match piece {
                    Piece::Item(j) => {
                        if let Some(mut it) = old_items[j].take() {
                            if after {
                                shift_item(&mut it, delta);
                            }
                            items.push(it);
                        }
                    }
                    Piece::Broken(j) => {
                        if let Some(mut b) = old_broken[j].take() {
                            if after {
                                sh(&mut b.range, delta);
                            }
                            broken.push(b);
                        }
                    }
                }
            }
            if !mid_done {
                push_mid(&mut items, &mut broken, &mut mid_items, &mut mid_broken, from_wrapped);
            }
            spec.items = items;
            spec.broken = broken;
            spec.range.end = (spec.range.end as isize + delta) as usize;
            out_specs.push(spec);
        }
        let mut out_comments = Vec::with_capacity(comments.len() + 4);
        let mut wrapped_comments = self.wrapped.file.comments.into_iter();
        let mut mid_pushed = false;
        for mut c in comments {
            if c.range.end <= self.old_mid.start {
                out_comments.push(c);
            } else if c.range.start >= self.old_mid.end {
                if !mid_pushed {
                    mid_pushed = true;
                    out_comments.extend(wrapped_comments.by_ref().map(|mut w| {
                        sh(&mut w.range, from_wrapped);
                        w
                    }));
                }
                sh(&mut c.range, delta);
                out_comments.push(c);
            }
        }
        if !mid_pushed {
            out_comments.extend(wrapped_comments.map(|mut w| {
                sh(&mut w.range, from_wrapped);
                w
            }));
        }
        let mut out_diags: Vec<Diagnostic> = Vec::with_capacity(diagnostics.len());
        for (mut d, fate) in diagnostics.into_iter().zip(&self.fates) {
            match fate {
                Fate::Keep | Fate::Shift => {
                    move_diag(&mut d, &self.old_mid, delta, matches!(fate, Fate::Shift));
                    out_diags.push(d);
                }
                Fate::Drop => {}
            }
        }
        for mut d in self.wrapped.diagnostics {
            shift_diag(&mut d, from_wrapped);
            out_diags.push(d);
        }
        let reparsed = self.new_mid.len();
        (
            Parsed {
                file: File { specs: out_specs, comments: out_comments },
                diagnostics: out_diags,
            },
            Reuse::Partial(reparsed),
        )
    }
}

fn push_mid(
    items: &mut Vec<Item>,
    broken: &mut Vec<BrokenItem>,
    mid_items: &mut Vec<Item>,
    mid_broken: &mut Vec<BrokenItem>,
    delta: isize,
) {
    for mut it in mid_items.drain(..) {
        shift_item(&mut it, delta);
        items.push(it);
    }
    for mut b in mid_broken.drain(..) {
        sh(&mut b.range, delta);
        broken.push(b);
    }
}

/// Whether the first token (or comment) of `src[from..]` ends before `cs`, with at least
/// one byte before `cs` after it, so that an edit at `cs` cannot change it.
fn first_token_untouched(src: &str, from: usize, cs: usize) -> bool {
    let Some(head) = src.get(from..cs) else { return false };
    lex(head).first().is_some_and(|t| t.end < head.len())
}

/// Whether a stretch of a spec body, parsed on its own, splits into the same items as
/// inside the whole text: it ends in white space, no comment runs past its end, its
/// brackets (and its braces alone) never close more than they opened and end balanced,
/// it holds no `spec`, and it does not end with a doc comment (which would document the
/// next item).
fn stretch_is_closed(mid: &str) -> bool {
    if mid.bytes().last().is_some_and(|c| !crate::parser::is_space(c)) {
        return false;
    }
    let toks = lex(mid);
    let (mut depth, mut braces) = (0isize, 0isize);
    for t in &toks {
        if t.end == mid.len() {
            return false;
        }
        let text = &mid[t.start..t.end];
        match (t.kind, text) {
            (Kind::Word, "spec") => return false,
            (Kind::Punct, "(" | "[") => depth += 1,
            (Kind::Punct, "{") => {
                depth += 1;
                braces += 1;
            }
            (Kind::Punct, ")" | "]") => depth -= 1,
            (Kind::Punct, "}") => {
                depth -= 1;
                braces -= 1;
            }
            _ => {}
        }
        if depth < 0 || braces < 0 {
            return false;
        }
    }
    let last_code = toks.iter().rev().find(|t| !t.is_comment());
    depth == 0 && braces == 0 && last_code.is_none_or(|t| t.kind != Kind::Doc)
}

fn sh(r: &mut Range<usize>, d: isize) {
    r.start = (r.start as isize + d) as usize;
    r.end = (r.end as isize + d) as usize;
}

fn shift_diag(d: &mut Diagnostic, by: isize) {
    sh(&mut d.range, by);
    for l in &mut d.labels {
        sh(&mut l.range, by);
    }
}

/// Moves a kept diagnostic of the previous parse: its range by `delta` when it lies
/// after the stretch, and each label by `delta` when that label lies after the stretch (a
/// label may point elsewhere than its diagnostic).
fn move_diag(d: &mut Diagnostic, old_mid: &Range<usize>, delta: isize, after: bool) {
    if after {
        sh(&mut d.range, delta);
    }
    for l in &mut d.labels {
        if l.range.start >= old_mid.end {
            sh(&mut l.range, delta);
        }
    }
}

fn shift_spec(s: &mut Spec, d: isize) {
    shift_doc(&mut s.doc, d);
    sh(&mut s.name.range, d);
    s.items.iter_mut().for_each(|i| shift_item(i, d));
    s.broken.iter_mut().for_each(|b| sh(&mut b.range, d));
    sh(&mut s.range, d);
}

fn shift_doc(doc: &mut Option<Doc>, d: isize) {
    if let Some(doc) = doc {
        doc.ranges.iter_mut().for_each(|r| sh(r, d));
    }
}

fn shift_item(item: &mut Item, d: isize) {
    match item {
        Item::State(b) => {
            for v in &mut b.vars {
                shift_doc(&mut v.doc, d);
                sh(&mut v.name.range, d);
                sh(&mut v.ty_range, d);
                if let Some(r) = &mut v.domain {
                    sh(&mut r.lo.range, d);
                    sh(&mut r.hi.range, d);
                    sh(&mut r.range, d);
                }
                sh(&mut v.range, d);
            }
            sh(&mut b.range, d);
        }
        Item::Let(l) => {
            shift_doc(&mut l.doc, d);
            sh(&mut l.name.range, d);
            shift_formula(&mut l.formula, d);
            sh(&mut l.range, d);
        }
        Item::Task(t) => {
            shift_doc(&mut t.doc, d);
            shift_formula(&mut t.formula, d);
            sh(&mut t.keyword_range, d);
            sh(&mut t.range, d);
        }
        Item::Option(o) => {
            shift_doc(&mut o.doc, d);
            sh(&mut o.name.range, d);
            for f in o.fields.iter_mut().flatten() {
                sh(&mut f.name.range, d);
                match &mut f.value {
                    FieldValue::Argmax(r) => sh(r, d),
                    FieldValue::Formula(g) => shift_formula(g, d),
                }
                sh(&mut f.range, d);
            }
            sh(&mut o.range, d);
        }
        Item::Options(o) => {
            match &mut o.kind {
                OptionsKind::List(seqs) => {
                    for s in seqs {
                        s.legs.iter_mut().for_each(|l| sh(&mut l.range, d));
                        sh(&mut s.range, d);
                    }
                }
                OptionsKind::Sequences(v) | OptionsKind::Permutations(v) => {
                    v.iter_mut().for_each(|l| sh(&mut l.range, d));
                }
            }
            sh(&mut o.range, d);
        }
        Item::Learn(l) => {
            l.params.iter_mut().for_each(|p| shift_param(p, d));
            sh(&mut l.range, d);
        }
        Item::World(w) => {
            shift_doc(&mut w.doc, d);
            sh(&mut w.name_range, d);
            sh(&mut w.range, d);
        }
    }
}

fn shift_param(p: &mut Param, d: isize) {
    sh(&mut p.name.range, d);
    match &mut p.value {
        ParamValue::Number(n) => sh(&mut n.range, d),
        ParamValue::Word(w) => sh(&mut w.range, d),
        ParamValue::Group(ps, r) => {
            ps.iter_mut().for_each(|q| shift_param(q, d));
            sh(r, d);
        }
    }
    sh(&mut p.range, d);
}

fn shift_interval(iv: &mut Option<Interval>, d: isize) {
    if let Some(iv) = iv {
        sh(&mut iv.start.range, d);
        if let Some(e) = &mut iv.end {
            sh(&mut e.range, d);
        }
        sh(&mut iv.range, d);
    }
}

fn shift_formula(f: &mut Formula, d: isize) {
    // The parts that are not operands or intervals; those follow, for every kind.
    match &mut f.kind {
        FormulaKind::Name(id) => sh(&mut id.range, d),
        FormulaKind::Compare { first, rest } => {
            shift_expr(first, d);
            for (_, r, e) in rest {
                sh(r, d);
                shift_expr(e, d);
            }
        }
        _ => {}
    }
    if let Some(iv) = f.kind.interval_mut() {
        shift_interval(iv, d);
    }
    for g in f.operands_mut() {
        shift_formula(g, d);
    }
    sh(&mut f.range, d);
}

fn shift_expr(e: &mut Expr, d: isize) {
    match &mut e.kind {
        ExprKind::Number(n) => sh(&mut n.range, d),
        ExprKind::Name(id) => sh(&mut id.range, d),
        ExprKind::Neg(a) | ExprKind::Call(_, a) | ExprKind::Paren(a) => shift_expr(a, d),
        ExprKind::Binary(_, a, b) => {
            shift_expr(a, d);
            shift_expr(b, d);
        }
    }
    sh(&mut e.range, d);
}
