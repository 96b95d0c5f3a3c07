//! The syntax tree from pest's pairs, with the height and nesting limits.

use super::*;

pub(super) fn ident(p: &Pair<'_, Rule>, offset: usize) -> Ident {
    let s = p.as_span();
    Ident { name: s.as_str().to_string(), range: s.start() + offset..s.end() + offset }
}

pub(super) fn make_doc(docs: Vec<Pair<'_, Rule>>, offset: usize) -> Option<Doc> {
    if docs.is_empty() {
        return None;
    }
    let mut doc = Doc::default();
    for d in docs {
        let s = d.as_span();
        let text = s.as_str().trim_start_matches("///").trim_end_matches('\r');
        doc.lines.push(text.strip_prefix(' ').unwrap_or(text).to_string());
        doc.ranges.push(s.start() + offset..s.end() + offset);
    }
    Some(doc)
}

/// Builds syntax nodes from pest pairs of one item; `offset` is the item's byte offset.
pub(super) struct Builder<'t> {
    pub(super) offset: usize,
    /// End offsets of every token of the file, ascending: pest spans may include trailing
    /// whitespace and comments, and node ranges end at their last token instead.
    pub(super) ends: &'t [usize],
    pub(super) diagnostics: Vec<Diagnostic>,
}

pub(super) type Res<T> = Result<T, Fail>;

/// An operand of a product, with the operator before it (`None` for the first) and its
/// height.
pub(super) type Factor = (Option<BinOp>, (Expr, usize));

/// A formula operator: prefix (`!`, `always`, `eventually`, `once`, `historically`,
/// `prev`, `next`) or infix.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum OpKind {
    Not,
    Always,
    Eventually,
    Once,
    Historically,
    Prev,
    Next,
    Implies,
    Or,
    And,
    Until,
    Since,
}

impl OpKind {
    /// Whether the operator comes before its one operand.
    pub(super) fn is_prefix(self) -> bool {
        matches!(
            self,
            OpKind::Not
                | OpKind::Always
                | OpKind::Eventually
                | OpKind::Once
                | OpKind::Historically
                | OpKind::Prev
                | OpKind::Next
        )
    }

    /// Whether the operator takes an interval.
    pub(super) fn takes_interval(self) -> bool {
        matches!(
            self,
            OpKind::Always
                | OpKind::Eventually
                | OpKind::Once
                | OpKind::Historically
                | OpKind::Until
                | OpKind::Since
        )
    }

    /// The prefix operator applied to `b`.
    pub(super) fn apply(self, interval: Option<Interval>, b: Box<Formula>) -> FormulaKind {
        match self {
            OpKind::Not => FormulaKind::Not(b),
            OpKind::Always => FormulaKind::Always(interval, b),
            OpKind::Once => FormulaKind::Once(interval, b),
            OpKind::Historically => FormulaKind::Historically(interval, b),
            OpKind::Prev => FormulaKind::Prev(b),
            OpKind::Next => FormulaKind::Next(b),
            _ => FormulaKind::Eventually(interval, b),
        }
    }
}

/// A formula operator with its byte range (keyword and interval) and interval.
pub(super) struct Op {
    pub(super) kind: OpKind,
    pub(super) range: Range<usize>,
    pub(super) interval: Option<Interval>,
}

/// One element of a formula's flat sequence.
pub(super) enum Piece {
    Op(Op),
    Operand(Formula, usize),
}

/// One element of an expression's flat sequence.
pub(super) enum EPiece {
    /// A prefix `-` starting at this offset.
    Neg(usize),
    /// `+` or `-` between terms.
    Add(BinOp),
    /// `*` or `/` between factors.
    Mul(BinOp),
    /// An operand with its height.
    Operand(Expr, usize),
}

impl Builder<'_> {
    pub(super) fn range(&self, p: &Pair<'_, Rule>) -> Range<usize> {
        let s = p.as_span();
        let (start, mut end) = (s.start() + self.offset, s.end() + self.offset);
        let k = self.ends.partition_point(|&e| e <= end);
        if k > 0 && self.ends[k - 1] > start {
            end = self.ends[k - 1];
        }
        start..end
    }

    pub(super) fn number(&self, p: &Pair<'_, Rule>) -> NumberLit {
        let text = p.as_str().to_string();
        NumberLit { value: text.parse().unwrap_or(f64::NAN), text, range: self.range(p) }
    }

    /// `-` and a number (white space between them dropped from the text).
    pub(super) fn neg_number(&self, p: &Pair<'_, Rule>) -> NumberLit {
        let text: String = p.as_str().split_whitespace().collect();
        NumberLit { value: text.parse().unwrap_or(f64::NAN), text, range: self.range(p) }
    }

    pub(super) fn too_tall(&self, range: Range<usize>) -> Fail {
        Fail(
            Diagnostic::new(
                "HSTL001",
                range,
                format!("formula or expression too deeply nested (more than {MAX_HEIGHT} levels)"),
            )
            .with_help("split it into several `let`s"),
        )
    }

    pub(super) fn item(&mut self, p: Pair<'_, Rule>) -> Res<Item> {
        let range = self.range(&p);
        let rule = p.as_rule();
        let mut docs = Vec::new();
        let mut rest = Vec::new();
        for c in p.into_inner() {
            if c.as_rule() == Rule::doc { docs.push(c) } else { rest.push(c) }
        }
        let doc = make_doc(docs, self.offset);
        Ok(match rule {
            Rule::state_item => {
                let mut vars = Vec::new();
                for v in rest.into_iter().filter(|c| c.as_rule() == Rule::var) {
                    vars.push(self.var(v));
                }
                Item::State(StateBlock { vars, range })
            }
            Rule::let_item => {
                let name =
                    rest.iter().find(|c| c.as_rule() == Rule::ident).map(|c| ident(c, self.offset));
                let f = rest.into_iter().find(|c| c.as_rule() == Rule::formula);
                match (name, f) {
                    (Some(name), Some(f)) => {
                        let (formula, _) = self.formula(f)?;
                        Item::Let(Let { doc, name, formula, range })
                    }
                    _ => return Err(self.internal(range)),
                }
            }
            Rule::task_item => {
                let kw = rest.iter().find(|c| c.as_rule() == Rule::k_task).map(|c| self.range(c));
                let f = rest.into_iter().find(|c| c.as_rule() == Rule::formula);
                match (kw, f) {
                    (Some(keyword_range), Some(f)) => {
                        let (formula, _) = self.formula(f)?;
                        Item::Task(Task { doc, formula, keyword_range, range })
                    }
                    _ => return Err(self.internal(range)),
                }
            }
            Rule::option_item => {
                let mut name = None;
                let mut fields = None;
                for c in rest {
                    match c.as_rule() {
                        Rule::ident => name = Some(ident(&c, self.offset)),
                        Rule::option_body => {
                            let mut fs = Vec::new();
                            for f in c.into_inner() {
                                fs.push(self.field(f)?);
                            }
                            fields = Some(fs);
                        }
                        _ => {}
                    }
                }
                let Some(name) = name else { return Err(self.internal(range)) };
                Item::Option(OptionDecl { doc, name, fields, range })
            }
            Rule::options_item => {
                let mut kind = None;
                for c in rest {
                    match c.as_rule() {
                        Rule::options_list => {
                            let mut seqs = Vec::new();
                            for s in c.into_inner() {
                                let r = self.range(&s);
                                let bracketed = s.as_str().starts_with('[');
                                let legs = s.into_inner().map(|i| ident(&i, self.offset)).collect();
                                seqs.push(SeqItem { legs, bracketed, range: r });
                            }
                            kind = Some(OptionsKind::List(seqs));
                        }
                        Rule::options_gen => {
                            let mut perm = false;
                            let mut names = Vec::new();
                            for g in c.into_inner() {
                                match g.as_rule() {
                                    Rule::gen_kind => perm = g.as_str() == "permutations",
                                    Rule::ident => names.push(ident(&g, self.offset)),
                                    _ => {}
                                }
                            }
                            kind = Some(if perm {
                                OptionsKind::Permutations(names)
                            } else {
                                OptionsKind::Sequences(names)
                            });
                        }
                        _ => {}
                    }
                }
                let Some(kind) = kind else { return Err(self.internal(range)) };
                Item::Options(OptionsItem { kind, range })
            }
            Rule::learn_item => {
                let params = rest
                    .into_iter()
                    .filter(|c| c.as_rule() == Rule::param)
                    .map(|c| self.param(c))
                    .collect::<Res<Vec<_>>>()?;
                Item::Learn(Learn { params, range })
            }
            Rule::world_item => {
                let Some(lit) = rest.iter().find(|c| c.as_rule() == Rule::string) else {
                    return Err(self.internal(range));
                };
                let name_range = self.range(lit);
                let name = unescape(lit.as_str());
                Item::World(WorldItem { doc, name, name_range, range })
            }
            _ => return Err(self.internal(range)),
        })
    }

    pub(super) fn internal(&self, range: Range<usize>) -> Fail {
        Fail(Diagnostic::new("HSTL001", range, "could not read this item"))
    }

    pub(super) fn var(&self, p: Pair<'_, Rule>) -> StateVar {
        let range = self.range(&p);
        let mut docs = Vec::new();
        let mut name = Ident { name: String::new(), range: range.clone() };
        let mut ty = VarType::Int;
        let mut ty_range = range.clone();
        let mut domain = None;
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::doc => docs.push(c),
                Rule::ident => name = ident(&c, self.offset),
                Rule::var_type => {
                    ty_range = self.range(&c);
                    ty = match c.as_str() {
                        "int" => VarType::Int,
                        "time" => VarType::Time,
                        _ => VarType::Float,
                    };
                }
                Rule::range_lit => {
                    let r = self.range(&c);
                    let mut nums = Vec::new();
                    let mut inclusive = false;
                    for x in c.into_inner() {
                        match x.as_rule() {
                            Rule::number => nums.push(self.number(&x)),
                            Rule::neg_number => nums.push(self.neg_number(&x)),
                            Rule::range_op => inclusive = x.as_str() == "..=",
                            _ => {}
                        }
                    }
                    if let (Some(hi), Some(lo)) = (nums.pop(), nums.pop()) {
                        domain = Some(RangeLit { lo, hi, inclusive, range: r });
                    }
                }
                _ => {}
            }
        }
        StateVar { doc: make_doc(docs, self.offset), name, ty, ty_range, domain, range }
    }

    pub(super) fn field(&mut self, p: Pair<'_, Rule>) -> Res<OptionField> {
        let range = self.range(&p);
        let mut name = None;
        let mut value = None;
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::ident => name = Some(ident(&c, self.offset)),
                Rule::field_value => {
                    let r = self.range(&c);
                    let inner = c.into_inner().next();
                    value = Some(match inner {
                        Some(f) if f.as_rule() == Rule::formula => {
                            FieldValue::Formula(self.formula(f)?.0)
                        }
                        _ => FieldValue::Argmax(r),
                    });
                }
                _ => {}
            }
        }
        match (name, value) {
            (Some(name), Some(value)) => Ok(OptionField { name, value, range }),
            _ => Err(self.internal(range)),
        }
    }

    pub(super) fn param(&self, p: Pair<'_, Rule>) -> Res<Param> {
        let range = self.range(&p);
        let mut name = None;
        let mut value = None;
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::param_name => name = Some(ident(&c, self.offset)),
                Rule::param_value => {
                    let Some(v) = c.into_inner().next() else { continue };
                    value = Some(match v.as_rule() {
                        Rule::number => ParamValue::Number(self.number(&v)),
                        Rule::neg_number => ParamValue::Number(self.neg_number(&v)),
                        Rule::ident => ParamValue::Word(ident(&v, self.offset)),
                        _ => {
                            let r = self.range(&v);
                            let ps =
                                v.into_inner().map(|q| self.param(q)).collect::<Res<Vec<_>>>()?;
                            ParamValue::Group(ps, r)
                        }
                    });
                }
                _ => {}
            }
        }
        match (name, value) {
            (Some(name), Some(value)) => Ok(Param { name, value, range }),
            _ => Err(self.internal(range)),
        }
    }

    pub(super) fn interval(&self, p: Pair<'_, Rule>) -> Interval {
        let range = self.range(&p);
        let mut nums = Vec::new();
        let mut inclusive = false;
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::number => nums.push(self.number(&c)),
                Rule::incl_op => inclusive = true,
                _ => {}
            }
        }
        let mut it = nums.into_iter();
        let start = it.next().unwrap_or(NumberLit {
            value: 0.0,
            text: "0".into(),
            range: range.start..range.start,
        });
        Interval { start, end: it.next(), inclusive, range }
    }

    /// Builds a formula from a `formula` pair (a flat sequence of prefix operators,
    /// operands and infix operators) and returns it with its height.
    pub(super) fn formula(&mut self, p: Pair<'_, Rule>) -> Res<(Formula, usize)> {
        // Fast path for a lone operand, the common case, without the bookkeeping below.
        let mut kids = p.clone().into_inner();
        if let (Some(only), None) = (kids.next(), kids.next()) {
            return self.primary(only);
        }
        let range = self.range(&p);
        let mut kids = p.into_inner();
        self.assemble(range, &mut |b: &mut Self| kids.next().map(|c| b.piece(c)))
    }

    /// One child of a `formula` pair as a piece: an operator or an operand.
    pub(super) fn piece(&mut self, c: Pair<'_, Rule>) -> Res<Piece> {
        let kind = match c.as_rule() {
            Rule::not_op => OpKind::Not,
            Rule::always_op => OpKind::Always,
            Rule::eventually_op => OpKind::Eventually,
            Rule::once_op => OpKind::Once,
            Rule::historically_op => OpKind::Historically,
            Rule::prev_op => OpKind::Prev,
            Rule::next_op => OpKind::Next,
            Rule::implies_op => OpKind::Implies,
            Rule::or_op => OpKind::Or,
            Rule::and_op => OpKind::And,
            Rule::until_op => OpKind::Until,
            Rule::since_op => OpKind::Since,
            _ => {
                let (f, h) = self.primary(c)?;
                return Ok(Piece::Operand(f, h));
            }
        };
        let range = self.range(&c);
        let interval = if kind.takes_interval() {
            c.into_inner().find(|c| c.as_rule() == Rule::interval).map(|i| self.interval(i))
        } else {
            None
        };
        Ok(Piece::Op(Op { kind, range, interval }))
    }

    /// Builds a formula from its pieces in source order (prefix operators, operands and
    /// infix operators), applying precedence; `range` is the whole formula's, for errors.
    pub(super) fn assemble(
        &mut self,
        range: Range<usize>,
        next: &mut dyn FnMut(&mut Self) -> Option<Res<Piece>>,
    ) -> Res<(Formula, usize)> {
        // Operands (each with its prefix operators) and the infix operators between them.
        let mut operands: Vec<(Formula, usize)> = Vec::new();
        let mut ops: Vec<Op> = Vec::new();
        let mut prefixes: Vec<Op> = Vec::new();
        while let Some(piece) = next(self) {
            match piece? {
                Piece::Op(op) if op.kind.is_prefix() => {
                    if prefixes.len() >= MAX_HEIGHT {
                        return Err(self.too_tall(range));
                    }
                    prefixes.push(op);
                }
                Piece::Op(op) => ops.push(op),
                Piece::Operand(mut f, mut h) => {
                    for op in prefixes.drain(..).rev() {
                        let r = op.range.start..f.range.end;
                        let kind = op.kind.apply(op.interval, Box::new(f));
                        f = Formula { kind, range: r };
                        h += 1;
                    }
                    if h > MAX_HEIGHT {
                        return Err(self.too_tall(range));
                    }
                    operands.push((f, h));
                }
            }
        }
        if operands.len() != ops.len() + 1 {
            return Err(self.internal(range));
        }
        if !ops.iter().any(|op| op.kind == OpKind::Implies) {
            return self.disjunction(operands, ops);
        }
        // Split at `->` (loosest, right-associative), then `||`, then `&&`, then `until`
        // and `since`.
        let mut segments: Vec<(Formula, usize)> = Vec::new();
        let mut operands = operands.into_iter();
        let mut group: Vec<(Formula, usize)> = operands.next().into_iter().collect();
        let mut group_ops: Vec<Op> = Vec::new();
        for (op, rhs) in ops.into_iter().zip(operands) {
            if op.kind == OpKind::Implies {
                segments.push(
                    self.disjunction(std::mem::take(&mut group), std::mem::take(&mut group_ops))?,
                );
            } else {
                group_ops.push(op);
            }
            group.push(rhs);
        }
        segments.push(self.disjunction(group, group_ops)?);
        let (mut acc, mut h) = segments.pop().ok_or_else(|| self.internal(range.clone()))?;
        while let Some((lhs, hl)) = segments.pop() {
            h = h.max(hl) + 1;
            if h > MAX_HEIGHT {
                return Err(self.too_tall(range));
            }
            let r = lhs.range.start..acc.range.end;
            acc = Formula { kind: FormulaKind::Implies(Box::new(lhs), Box::new(acc)), range: r };
        }
        Ok((acc, h))
    }

    /// Operands joined by `||`, `&&`, `until` and `since` (no `->`): `until` and `since`
    /// chains are folded as they come, grouped by `&&`, and those by `||`.
    pub(super) fn disjunction(
        &mut self,
        operands: Vec<(Formula, usize)>,
        ops: Vec<Op>,
    ) -> Res<(Formula, usize)> {
        let mut operands = operands.into_iter();
        let Some(mut chain) = operands.next() else {
            return Err(Fail(Diagnostic::new("HSTL001", 0..0, "could not read this formula")));
        };
        // `until` and `since` operators folded into `chain` so far, and the first one's word.
        let mut untils = 0;
        let mut first = "until";
        let mut and_parts: Vec<(Formula, usize)> = Vec::new();
        let mut or_parts: Vec<(Formula, usize)> = Vec::new();
        for (op, rhs) in ops.into_iter().zip(operands) {
            match op.kind {
                OpKind::Or => {
                    and_parts.push(std::mem::replace(&mut chain, rhs));
                    or_parts.push(self.nary(std::mem::take(&mut and_parts), false)?);
                    untils = 0;
                }
                OpKind::And => {
                    and_parts.push(std::mem::replace(&mut chain, rhs));
                    untils = 0;
                }
                _ => {
                    let word = if op.kind == OpKind::Since { "since" } else { "until" };
                    if untils == 0 {
                        first = word;
                    }
                    chain = self.until(chain, op, rhs, untils, first)?;
                    untils += 1;
                }
            }
        }
        and_parts.push(chain);
        or_parts.push(self.nary(and_parts, false)?);
        self.nary(or_parts, true)
    }

    /// `acc until rhs` (or `since`), where `acc` already folds `count` `until`s and
    /// `since`s, the first of them `first` (a chain is reported as HSTL021 at its second
    /// operator and built from the left).
    pub(super) fn until(
        &mut self,
        (acc, h): (Formula, usize),
        op: Op,
        (rhs, hr): (Formula, usize),
        count: usize,
        first: &str,
    ) -> Res<(Formula, usize)> {
        let since = op.kind == OpKind::Since;
        if count == 1 {
            let word = if since { "since" } else { "until" };
            let message = if word == first {
                format!("`{word}` is not chainable")
            } else {
                format!("`{first}` and `{word}` do not chain")
            };
            self.diagnostics.push(
                Diagnostic::new("HSTL021", op.range.clone(), message)
                    .with_label(acc.range.clone(), {
                        let article = if first == "until" { "an" } else { "a" };
                        format!("this is already {article} `{first}` formula")
                    })
                    .with_help(format!(
                        "add parentheses: `(a {first} b) {word} c` or `a {first} (b {word} c)`"
                    )),
            );
        }
        let h = h.max(hr) + 1;
        if h > MAX_HEIGHT {
            return Err(self.too_tall(acc.range.start..rhs.range.end));
        }
        let r = acc.range.start..rhs.range.end;
        let (a, b) = (Box::new(acc), Box::new(rhs));
        let kind = if since {
            FormulaKind::Since(a, op.interval, b)
        } else {
            FormulaKind::Until(a, op.interval, b)
        };
        Ok((Formula { kind, range: r }, h))
    }

    /// One operand, or an `Or`/`And` node over two or more.
    pub(super) fn nary(&self, mut parts: Vec<(Formula, usize)>, or: bool) -> Res<(Formula, usize)> {
        if parts.len() == 1 {
            return parts.pop().ok_or_else(|| self.internal(0..0));
        }
        let h = parts.iter().map(|p| p.1).max().unwrap_or(0) + 1;
        let r = match (parts.first(), parts.last()) {
            (Some(a), Some(b)) => a.0.range.start..b.0.range.end,
            _ => return Err(self.internal(0..0)),
        };
        let fs = parts.into_iter().map(|p| p.0).collect();
        let kind = if or { FormulaKind::Or(fs) } else { FormulaKind::And(fs) };
        Ok((Formula { kind, range: r }, h))
    }

    /// An operand of a formula: `true`, `false`, a name, a comparison or `( formula )`.
    pub(super) fn primary(&mut self, p: Pair<'_, Rule>) -> Res<(Formula, usize)> {
        let range = self.range(&p);
        match p.as_rule() {
            Rule::k_true => Ok((Formula { kind: FormulaKind::True, range }, 1)),
            Rule::k_false => Ok((Formula { kind: FormulaKind::False, range }, 1)),
            Rule::ident => {
                Ok((Formula { kind: FormulaKind::Name(ident(&p, self.offset)), range }, 1))
            }
            Rule::paren_f => {
                let f = p.into_inner().next().ok_or_else(|| self.internal(range.clone()))?;
                let (f, h) = self.formula(f)?;
                Ok((Formula { kind: FormulaKind::Paren(Box::new(f)), range }, h + 1))
            }
            Rule::comparison => {
                let mut it = p.into_inner();
                let e0 = it.next().ok_or_else(|| self.internal(range.clone()))?;
                let (first, mut h) = self.expr(e0)?;
                let mut rest = Vec::new();
                while let (Some(op), Some(e)) = (it.next(), it.next()) {
                    let cmp = match op.as_str() {
                        "<" => CmpOp::Lt,
                        "<=" => CmpOp::Le,
                        ">" => CmpOp::Gt,
                        ">=" => CmpOp::Ge,
                        "==" => CmpOp::Eq,
                        _ => CmpOp::Ne,
                    };
                    let (e, he) = self.expr(e)?;
                    h = h.max(he);
                    rest.push((cmp, self.range(&op), e));
                }
                Ok((Formula { kind: FormulaKind::Compare { first, rest }, range }, h + 1))
            }
            _ => Err(self.internal(range)),
        }
    }

    /// Builds an expression from an `expr` pair (prefix `-`, operands and `+ - * /`) and
    /// returns it with its height.
    pub(super) fn expr(&mut self, p: Pair<'_, Rule>) -> Res<(Expr, usize)> {
        // Fast path for a lone operand, the common case.
        let mut kids = p.clone().into_inner();
        if let (Some(only), None) = (kids.next(), kids.next()) {
            return self.operand(only);
        }
        let range = self.range(&p);
        let mut kids = p.into_inner();
        self.assemble_expr(range, &mut |b: &mut Self| {
            kids.next().map(|c| match c.as_rule() {
                Rule::neg_op => Ok(EPiece::Neg(b.range(&c).start)),
                Rule::add_op => Ok(EPiece::Add(if c.as_str().starts_with('+') {
                    BinOp::Add
                } else {
                    BinOp::Sub
                })),
                Rule::mul_op => {
                    Ok(EPiece::Mul(if c.as_str() == "*" { BinOp::Mul } else { BinOp::Div }))
                }
                _ => b.operand(c).map(|(e, h)| EPiece::Operand(e, h)),
            })
        })
    }

    /// Builds an expression from its pieces in source order, applying precedence;
    /// `range` is the whole expression's, for errors.
    pub(super) fn assemble_expr(
        &mut self,
        range: Range<usize>,
        next: &mut dyn FnMut(&mut Self) -> Option<Res<EPiece>>,
    ) -> Res<(Expr, usize)> {
        // Terms joined by `+`/`-`; each term is operands joined by `*`/`/`.
        let mut sums: Vec<(Option<BinOp>, Vec<Factor>)> = vec![(None, Vec::new())];
        let mut negs: Vec<usize> = Vec::new();
        let mut pending: Option<BinOp> = None;
        while let Some(piece) = next(self) {
            match piece? {
                EPiece::Neg(start) => {
                    if negs.len() >= MAX_HEIGHT {
                        return Err(self.too_tall(range));
                    }
                    negs.push(start);
                }
                EPiece::Add(op) => sums.push((Some(op), Vec::new())),
                EPiece::Mul(op) => pending = Some(op),
                EPiece::Operand(mut e, mut h) => {
                    for start in negs.drain(..).rev() {
                        let r = start..e.range.end;
                        e = Expr { kind: ExprKind::Neg(Box::new(e)), range: r };
                        h += 1;
                    }
                    if let Some(last) = sums.last_mut() {
                        last.1.push((pending.take(), (e, h)));
                    }
                }
            }
        }
        let mut acc: Option<(Expr, usize)> = None;
        for (add, factors) in sums {
            let mut term: Option<(Expr, usize)> = None;
            for (mul, (e, h)) in factors {
                term = Some(match (term, mul) {
                    (Some((a, ha)), Some(op)) => self.binary(op, a, ha, e, h, &range)?,
                    _ => (e, h),
                });
            }
            let Some((t, ht)) = term else { return Err(self.internal(range)) };
            acc = Some(match (acc, add) {
                (Some((a, ha)), Some(op)) => self.binary(op, a, ha, t, ht, &range)?,
                _ => (t, ht),
            });
        }
        acc.ok_or_else(|| self.internal(range))
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn binary(
        &self,
        op: BinOp,
        a: Expr,
        ha: usize,
        b: Expr,
        hb: usize,
        whole: &Range<usize>,
    ) -> Res<(Expr, usize)> {
        let h = ha.max(hb) + 1;
        if h > MAX_HEIGHT {
            return Err(self.too_tall(whole.clone()));
        }
        let r = a.range.start..b.range.end;
        Ok((Expr { kind: ExprKind::Binary(op, Box::new(a), Box::new(b)), range: r }, h))
    }

    /// An operand of an expression: a number, a name, `( expr )` or a call.
    pub(super) fn operand(&mut self, c: Pair<'_, Rule>) -> Res<(Expr, usize)> {
        let range = self.range(&c);
        match c.as_rule() {
            Rule::number => Ok((Expr { kind: ExprKind::Number(self.number(&c)), range }, 1)),
            Rule::ident => Ok((Expr { kind: ExprKind::Name(ident(&c, self.offset)), range }, 1)),
            Rule::paren_e => {
                let f = c.into_inner().next().ok_or_else(|| self.internal(range.clone()))?;
                let (e, h) = self.expr(f)?;
                Ok((Expr { kind: ExprKind::Paren(Box::new(e)), range }, h + 1))
            }
            Rule::call => {
                let mut it = c.into_inner();
                let func = it.next().ok_or_else(|| self.internal(range.clone()))?;
                let func = if func.as_str() == "abs" { Func::Abs } else { Func::Sqrt };
                let arg = it.next().ok_or_else(|| self.internal(range.clone()))?;
                let (e, h) = self.expr(arg)?;
                Ok((Expr { kind: ExprKind::Call(func, Box::new(e)), range }, h + 1))
            }
            _ => Err(self.internal(range)),
        }
    }
}
