//! The syntax tree: what the text says, with a byte range on every node and name.
//!
//! Nothing here is resolved: names are plain [`Ident`]s. Parentheses are kept
//! ([`FormulaKind::Paren`], [`ExprKind::Paren`]) so that a formatter can reproduce them.

use std::ops::Range;

/// A name with the byte range where it is written.
#[derive(Clone, Debug, PartialEq)]
pub struct Ident {
    /// The name.
    pub name: String,
    /// Byte range of the name.
    pub range: Range<usize>,
}

/// A number literal with its source text.
#[derive(Clone, Debug, PartialEq)]
pub struct NumberLit {
    /// The value (`f64` parse of the text).
    pub value: f64,
    /// The text as written, such as `1e-6`.
    pub text: String,
    /// Byte range of the literal (including a leading `-` where the grammar allows one).
    pub range: Range<usize>,
}

impl NumberLit {
    /// The value as an unsigned integer, if the literal is written as one (digits only).
    pub fn as_integer(&self) -> Option<u64> {
        if self.text.bytes().all(|b| b.is_ascii_digit()) { self.text.parse().ok() } else { None }
    }
}

/// What kind of comment a [`Comment`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CommentKind {
    /// `// ...` (also `//// ...`).
    Line,
    /// `/* ... */`, possibly nested.
    Block,
    /// `/// ...`, documenting the next item.
    Doc,
}

/// One comment of the file, kept so that a formatter can put it back.
#[derive(Clone, Debug, PartialEq)]
pub struct Comment {
    /// Line, block or doc comment.
    pub kind: CommentKind,
    /// Byte range, from the first `/` to the end of the line or the closing `*/`.
    pub range: Range<usize>,
}

/// The doc comment lines (`///`) in front of a node.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Doc {
    /// The text of each line without `///` and one leading space.
    pub lines: Vec<String>,
    /// Byte range of each line.
    pub ranges: Vec<Range<usize>>,
}

impl Doc {
    /// The lines joined with newlines.
    pub fn text(&self) -> String {
        self.lines.join("\n")
    }
}

/// A whole source file.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct File {
    /// The specs, in source order.
    pub specs: Vec<Spec>,
    /// Every comment of the file (line, block and doc), in source order.
    pub comments: Vec<Comment>,
}

/// `spec Name { ... }`.
#[derive(Clone, Debug, PartialEq)]
pub struct Spec {
    /// Doc comment in front of `spec`.
    pub doc: Option<Doc>,
    /// The spec's name; empty when the header could not be parsed.
    pub name: Ident,
    /// The items that parsed, in source order; broken items are left out.
    pub items: Vec<Item>,
    /// Items that did not parse (already reported), so that later passes can stay quiet
    /// about what they may have declared.
    pub broken: Vec<BrokenItem>,
    /// Byte range from the first doc line (or `spec`) to the closing brace.
    pub range: Range<usize>,
}

/// An item that did not parse: its keyword and the names it seems to declare.
#[derive(Clone, Debug, PartialEq)]
pub struct BrokenItem {
    /// The first word of the item (`let`, `task`, `state`, ...), if it starts with one.
    pub keyword: Option<String>,
    /// Names it seems to declare: the name after `let`/`option`, or state variable names.
    pub names: Vec<String>,
    /// Byte range of the item.
    pub range: Range<usize>,
}

/// One item of a spec body.
#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    /// `state { ... }`.
    State(StateBlock),
    /// `let Name = formula;`.
    Let(Let),
    /// `task formula;`.
    Task(Task),
    /// `option Name;` or `option Name { ... }`.
    Option(OptionDecl),
    /// `options ...`.
    Options(OptionsItem),
    /// `learn { ... }`.
    Learn(Learn),
    /// `world "NAME_OR_PATH";`.
    World(WorldItem),
}

impl Item {
    /// Byte range of the whole item.
    pub fn range(&self) -> Range<usize> {
        match self {
            Item::State(i) => i.range.clone(),
            Item::Let(i) => i.range.clone(),
            Item::Task(i) => i.range.clone(),
            Item::Option(i) => i.range.clone(),
            Item::Options(i) => i.range.clone(),
            Item::Learn(i) => i.range.clone(),
            Item::World(i) => i.range.clone(),
        }
    }
}

/// `world "four-rooms";` or `world "maps/yard.toml";`: the world the spec is written for,
/// a built-in world's name or a world file's path relative to the spec file.
#[derive(Clone, Debug, PartialEq)]
pub struct WorldItem {
    /// Doc comment.
    pub doc: Option<Doc>,
    /// The string's value: its text between the quotes, escapes (`\"`, `\\`) resolved.
    pub name: String,
    /// Byte range of the string, quotes included.
    pub name_range: Range<usize>,
    /// Byte range of the item (docs included).
    pub range: Range<usize>,
}

/// `state { var, ... }`.
#[derive(Clone, Debug, PartialEq)]
pub struct StateBlock {
    /// The variables, in order.
    pub vars: Vec<StateVar>,
    /// Byte range of the item.
    pub range: Range<usize>,
}

/// The declared type of a state variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VarType {
    /// `int`.
    Int,
    /// `float`.
    Float,
    /// `time`: the trace's time stamps, which make the spec a dense-time spec.
    Time,
}

/// `name: int in 0..=14`.
#[derive(Clone, Debug, PartialEq)]
pub struct StateVar {
    /// Doc comment.
    pub doc: Option<Doc>,
    /// Variable name.
    pub name: Ident,
    /// Declared type.
    pub ty: VarType,
    /// Byte range of the type keyword.
    pub ty_range: Range<usize>,
    /// The `in` range, if any.
    pub domain: Option<RangeLit>,
    /// Byte range of the declaration (docs included).
    pub range: Range<usize>,
}

/// `lo..hi` or `lo..=hi`.
#[derive(Clone, Debug, PartialEq)]
pub struct RangeLit {
    /// Lower bound.
    pub lo: NumberLit,
    /// Upper bound.
    pub hi: NumberLit,
    /// `..=` rather than `..`.
    pub inclusive: bool,
    /// Byte range of the whole range.
    pub range: Range<usize>,
}

/// `let Name = formula;`.
#[derive(Clone, Debug, PartialEq)]
pub struct Let {
    /// Doc comment.
    pub doc: Option<Doc>,
    /// The name being defined.
    pub name: Ident,
    /// The definition.
    pub formula: Formula,
    /// Byte range of the item (docs included).
    pub range: Range<usize>,
}

/// `task formula;`.
#[derive(Clone, Debug, PartialEq)]
pub struct Task {
    /// Doc comment.
    pub doc: Option<Doc>,
    /// The task formula.
    pub formula: Formula,
    /// Byte range of the `task` keyword.
    pub keyword_range: Range<usize>,
    /// Byte range of the item (docs included).
    pub range: Range<usize>,
}

/// `option Name;` (short form) or `option Name { field, ... }` (long form).
#[derive(Clone, Debug, PartialEq)]
pub struct OptionDecl {
    /// Doc comment.
    pub doc: Option<Doc>,
    /// The option's name.
    pub name: Ident,
    /// `None` for the short form.
    pub fields: Option<Vec<OptionField>>,
    /// Byte range of the item (docs included).
    pub range: Range<usize>,
}

/// `reach: f`, `init: f` or `terminate: argmax | f`.
#[derive(Clone, Debug, PartialEq)]
pub struct OptionField {
    /// The field name as written (the checker rejects unknown ones).
    pub name: Ident,
    /// The value.
    pub value: FieldValue,
    /// Byte range of the field.
    pub range: Range<usize>,
}

/// The value of an option field.
#[derive(Clone, Debug, PartialEq)]
pub enum FieldValue {
    /// `argmax`, with its byte range.
    Argmax(Range<usize>),
    /// A formula.
    Formula(Formula),
}

/// `options { ... }`, `options sequences(...);` or `options permutations(...);`.
#[derive(Clone, Debug, PartialEq)]
pub struct OptionsItem {
    /// Which form.
    pub kind: OptionsKind,
    /// Byte range of the item.
    pub range: Range<usize>,
}

/// The three forms of the `options` item.
#[derive(Clone, Debug, PartialEq)]
pub enum OptionsKind {
    /// An explicit list of options and sequences.
    List(Vec<SeqItem>),
    /// Every non-empty subsequence of the names.
    Sequences(Vec<Ident>),
    /// Every ordering of every non-empty subset of the names.
    Permutations(Vec<Ident>),
}

/// One entry of an explicit options list: `A` or `[A, B]`.
#[derive(Clone, Debug, PartialEq)]
pub struct SeqItem {
    /// The option names, in order.
    pub legs: Vec<Ident>,
    /// Written with brackets.
    pub bracketed: bool,
    /// Byte range of the entry.
    pub range: Range<usize>,
}

/// `learn { param, ... }`.
#[derive(Clone, Debug, PartialEq)]
pub struct Learn {
    /// The parameters as written.
    pub params: Vec<Param>,
    /// Byte range of the item.
    pub range: Range<usize>,
}

/// `name: value`.
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    /// The parameter name as written.
    pub name: Ident,
    /// The value.
    pub value: ParamValue,
    /// Byte range of the parameter.
    pub range: Range<usize>,
}

/// The value of a learning parameter.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamValue {
    /// A number (possibly negative, so that the checker can say it is out of range).
    Number(NumberLit),
    /// A word such as `paper` or `window`.
    Word(Ident),
    /// `{ name: value, ... }`, with the byte range of the braces.
    Group(Vec<Param>, Range<usize>),
}

/// A formula node.
#[derive(Clone, Debug, PartialEq)]
pub struct Formula {
    /// What it is.
    pub kind: FormulaKind,
    /// Byte range of the whole formula.
    pub range: Range<usize>,
}

impl Formula {
    /// The direct operands of this node, in source order: the one place that lists which
    /// kinds have which operands, so that walks over the tree need not.
    pub fn operands(&self) -> Vec<&Formula> {
        match &self.kind {
            FormulaKind::Not(a)
            | FormulaKind::Always(_, a)
            | FormulaKind::Eventually(_, a)
            | FormulaKind::Once(_, a)
            | FormulaKind::Historically(_, a)
            | FormulaKind::Prev(a)
            | FormulaKind::Next(a)
            | FormulaKind::Paren(a) => vec![a],
            FormulaKind::And(v) | FormulaKind::Or(v) => v.iter().collect(),
            FormulaKind::Implies(a, b)
            | FormulaKind::Until(a, _, b)
            | FormulaKind::Since(a, _, b) => {
                vec![a, b]
            }
            FormulaKind::True
            | FormulaKind::False
            | FormulaKind::Name(_)
            | FormulaKind::Compare { .. } => Vec::new(),
        }
    }

    /// [`Formula::operands`], mutable.
    pub fn operands_mut(&mut self) -> Vec<&mut Formula> {
        match &mut self.kind {
            FormulaKind::Not(a)
            | FormulaKind::Always(_, a)
            | FormulaKind::Eventually(_, a)
            | FormulaKind::Once(_, a)
            | FormulaKind::Historically(_, a)
            | FormulaKind::Prev(a)
            | FormulaKind::Next(a)
            | FormulaKind::Paren(a) => vec![a],
            FormulaKind::And(v) | FormulaKind::Or(v) => v.iter_mut().collect(),
            FormulaKind::Implies(a, b)
            | FormulaKind::Until(a, _, b)
            | FormulaKind::Since(a, _, b) => {
                vec![a, b]
            }
            FormulaKind::True
            | FormulaKind::False
            | FormulaKind::Name(_)
            | FormulaKind::Compare { .. } => Vec::new(),
        }
    }
}

impl FormulaKind {
    /// The interval slot of a temporal operator that takes one (`None` for other kinds);
    /// the slot itself holds `None` when the interval was left out.
    pub fn interval_mut(&mut self) -> Option<&mut Option<Interval>> {
        match self {
            FormulaKind::Always(i, _)
            | FormulaKind::Eventually(i, _)
            | FormulaKind::Once(i, _)
            | FormulaKind::Historically(i, _)
            | FormulaKind::Until(_, i, _)
            | FormulaKind::Since(_, i, _) => Some(i),
            _ => None,
        }
    }

    /// The interval of a temporal operator, when it has one written.
    pub fn interval(&self) -> Option<&Interval> {
        match self {
            FormulaKind::Always(i, _)
            | FormulaKind::Eventually(i, _)
            | FormulaKind::Once(i, _)
            | FormulaKind::Historically(i, _)
            | FormulaKind::Until(_, i, _)
            | FormulaKind::Since(_, i, _) => i.as_ref(),
            _ => None,
        }
    }
}

/// The kinds of formula.
#[derive(Clone, Debug, PartialEq)]
pub enum FormulaKind {
    /// `true`.
    True,
    /// `false`.
    False,
    /// A name in formula position (should name a `let`).
    Name(Ident),
    /// `e0 op1 e1 op2 e2 ...`: a comparison, possibly chained.
    Compare {
        /// The first expression.
        first: Expr,
        /// Each further operator (with its range) and expression.
        rest: Vec<(CmpOp, Range<usize>, Expr)>,
    },
    /// `!f`.
    Not(Box<Formula>),
    /// `always[I] f`.
    Always(Option<Interval>, Box<Formula>),
    /// `eventually[I] f`.
    Eventually(Option<Interval>, Box<Formula>),
    /// `f until[I] g`.
    Until(Box<Formula>, Option<Interval>, Box<Formula>),
    /// `once[I] f`: `f` held at some step of the past window.
    Once(Option<Interval>, Box<Formula>),
    /// `historically[I] f`: `f` held at every step of the past window.
    Historically(Option<Interval>, Box<Formula>),
    /// `f since[I] g`.
    Since(Box<Formula>, Option<Interval>, Box<Formula>),
    /// `prev f`: `f` one step back (`+inf` at the first step).
    Prev(Box<Formula>),
    /// `next f`: `f` one step ahead (`+inf` at the last step).
    Next(Box<Formula>),
    /// `f && g && ...` (two or more operands).
    And(Vec<Formula>),
    /// `f || g || ...` (two or more operands).
    Or(Vec<Formula>),
    /// `f -> g`.
    Implies(Box<Formula>, Box<Formula>),
    /// `(f)`.
    Paren(Box<Formula>),
}

/// A comparison operator, including the rejected `==` and `!=`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CmpOp {
    /// `<`.
    Lt,
    /// `<=`.
    Le,
    /// `>`.
    Gt,
    /// `>=`.
    Ge,
    /// `==` (rejected by the checker).
    Eq,
    /// `!=` (rejected by the checker).
    Ne,
}

impl CmpOp {
    /// The operator as written.
    pub fn as_str(self) -> &'static str {
        match self {
            CmpOp::Lt => "<",
            CmpOp::Le => "<=",
            CmpOp::Gt => ">",
            CmpOp::Ge => ">=",
            CmpOp::Eq => "==",
            CmpOp::Ne => "!=",
        }
    }
}

/// `[a..b]`, `[a..]` or `[a..=b]` as written.
#[derive(Clone, Debug, PartialEq)]
pub struct Interval {
    /// Start bound.
    pub start: NumberLit,
    /// End bound, absent for `[a..]`.
    pub end: Option<NumberLit>,
    /// `..=` rather than `..`.
    pub inclusive: bool,
    /// Byte range from `[` to `]`.
    pub range: Range<usize>,
}

/// An arithmetic expression node.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    /// What it is.
    pub kind: ExprKind,
    /// Byte range of the whole expression.
    pub range: Range<usize>,
}

/// A binary arithmetic operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    /// `+`.
    Add,
    /// `-`.
    Sub,
    /// `*`.
    Mul,
    /// `/`.
    Div,
}

/// A built-in function.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Func {
    /// `abs`.
    Abs,
    /// `sqrt`.
    Sqrt,
}

/// The kinds of expression.
#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    /// A number.
    Number(NumberLit),
    /// A name in expression position (should name a state variable).
    Name(Ident),
    /// `-e`.
    Neg(Box<Expr>),
    /// `e op e`, left-associative.
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// `abs(e)` or `sqrt(e)`.
    Call(Func, Box<Expr>),
    /// `(e)`.
    Paren(Box<Expr>),
}
