//! The online dense-time monitor's state as bytes ([`DenseMonitor::save`],
//! [`DenseMonitor::load`]): every operator's pieces and deques, checked on the way back.

use std::collections::VecDeque;

use super::super::saved::{self, Reader, SavedStateError, Writer};
use super::super::trace;
use super::super::until::{BoundedUntil, Pieces};
use super::super::{DenseFormula, DenseTraceBuilder};
use super::DenseMonitor;
use super::ops::*;

impl Dedup {
    fn save(&self, w: &mut Writer) {
        w.opt_f64(self.last);
    }

    fn load(r: &mut Reader<'_>) -> Result<Dedup, SavedStateError> {
        Ok(Dedup { last: r.opt_value("an operator's last value")? })
    }
}

impl Merge {
    fn save(&self, w: &mut Writer) {
        w.count(self.queues.len());
        for q in &self.queues {
            w.points(q.iter());
        }
        for &c in &self.cur {
            w.f64(c);
        }
        w.f64(self.acc);
        self.out.save(w);
    }

    /// Loads into a merge built for the formula (its fold and operand count).
    fn load(&mut self, r: &mut Reader<'_>) -> Result<(), SavedStateError> {
        let n = r.count(1, "a merge's operands")?;
        if n != self.queues.len() {
            return Err(r.bad(&format!(
                "a merge has {n} operands, and the formula's has {}",
                self.queues.len()
            )));
        }
        for q in &mut self.queues {
            *q = r.points("a merge's operand")?.into();
        }
        for c in &mut self.cur {
            *c = r.value("a merge's operand value")?;
        }
        self.acc = r.value("a since's running value")?;
        self.out = Dedup::load(r)?;
        Ok(())
    }
}

impl Win {
    fn save(&self, w: &mut Writer) {
        w.count(self.times.len());
        for (&t, &v) in self.times.iter().zip(&self.vals) {
            w.f64(t);
            w.f64(v);
        }
        for n in [self.base, self.i, self.j] {
            w.count(n);
        }
        w.count(self.dq.len());
        for &(k, v) in &self.dq {
            w.count(k);
            w.f64(v);
        }
        w.opt_f64(self.swept);
        self.out.save(w);
    }

    /// Loads into a window built for the formula (its direction, bounds and extreme); the
    /// monotone deque of a window whose pieces leave is checked against its recomputation.
    fn load(&mut self, r: &mut Reader<'_>) -> Result<(), SavedStateError> {
        let points = r.points("a window's pieces")?;
        self.times = points.iter().map(|p| p.0).collect();
        self.vals = points.iter().map(|p| p.1).collect();
        let max = usize::MAX >> 2;
        self.base = r.index(max, "a window's first piece")?;
        self.i = r.index(max, "a window's next piece to enter")?;
        self.j = r.index(max, "a window's next piece to leave")?;
        let rec = self.received();
        let fits = if self.ends {
            self.base <= self.j && self.j <= self.i && self.i <= rec
        } else {
            self.j == 0 && self.base <= self.i && self.i <= rec
        };
        if !fits {
            return Err(r.bad(&format!(
                "a window's positions do not fit together (pieces {} to {rec}, entered up to \
                 {}, left up to {})",
                self.base, self.i, self.j
            )));
        }
        let n = r.count(2, "a window's deque")?;
        let mut dq: VecDeque<(usize, f64)> = VecDeque::with_capacity(n);
        for _ in 0..n {
            let k = r.index(max, "a window's deque")?;
            let v = r.value("a window's deque")?;
            let ordered = dq.back().is_none_or(|&(p, q)| p < k && !self.ext.dominates(v, q));
            if !ordered || k >= self.i {
                return Err(r.bad("a window's deque is not monotone over the pieces entered"));
            }
            dq.push_back((k, v));
        }
        if self.ends {
            // Every piece from the next to leave to the next to enter is in the window.
            let mut want: VecDeque<(usize, f64)> = VecDeque::new();
            for k in self.j..self.i {
                let v = self.vals[k - self.base];
                while want.back().is_some_and(|&(_, q)| self.ext.dominates(v, q)) {
                    want.pop_back();
                }
                want.push_back((k, v));
            }
            if !super::super::until::same(&dq, &want) {
                return Err(r.bad("a window's deque is not that of its pieces"));
            }
        }
        self.dq = dq;
        self.swept = if r.flag("whether a window swept")? {
            Some(r.value("a window's last time")?)
        } else {
            None
        };
        self.out = Dedup::load(r)?;
        Ok(())
    }
}

impl SinceNode {
    fn save(&self, w: &mut Writer) {
        self.untimed.save(w);
        for win in [&self.reach, &self.hold].into_iter().flatten() {
            win.save(w);
        }
        if let Some(both) = &self.both {
            both.save(w);
        }
    }

    fn load(&mut self, r: &mut Reader<'_>) -> Result<(), SavedStateError> {
        self.untimed.load(r)?;
        for win in [&mut self.reach, &mut self.hold].into_iter().flatten() {
            win.load(r)?;
        }
        if let Some(both) = &mut self.both {
            both.load(r)?;
        }
        Ok(())
    }
}

impl UntilNode {
    fn save(&self, w: &mut Writer) {
        w.points(self.f.iter());
        w.points(self.g.iter());
        w.f64(self.decided);
        self.out.save(w);
    }

    fn load(&mut self, r: &mut Reader<'_>) -> Result<(), SavedStateError> {
        self.f = r.points("an until's left operand")?.into();
        self.g = r.points("an until's right operand")?.into();
        self.decided = r.value("an until's frontier")?;
        self.out = Dedup::load(r)?;
        Ok(())
    }
}

impl Op {
    /// The tag a saved state gives the operator.
    fn tag(&self) -> u64 {
        match self {
            Op::Expr => 0,
            Op::Cmp(_) => 1,
            Op::Constant(..) => 2,
            Op::Not(_) => 3,
            Op::Copy => 4,
            Op::Merge(_) => 5,
            Op::Win(_) => 6,
            Op::Since(_) => 7,
            Op::Bounded(_) => 8,
            Op::Until(_) => 9,
        }
    }

    fn save(&self, w: &mut Writer) {
        w.word(self.tag());
        match self {
            Op::Expr | Op::Copy => {}
            Op::Cmp(d) | Op::Constant(_, d) | Op::Not(d) => d.save(w),
            Op::Merge(m) => m.save(w),
            Op::Win(win) => win.save(w),
            Op::Since(s) => s.save(w),
            Op::Bounded(p) => {
                p.0.save(w);
                p.1.save(w);
            }
            Op::Until(u) => u.save(w),
        }
    }

    /// Loads into the operator built for the formula's node `i`.
    fn load(&mut self, r: &mut Reader<'_>, i: usize) -> Result<(), SavedStateError> {
        let tag = r.word("an operator")?;
        if tag != self.tag() {
            return Err(r.bad(&format!(
                "node {i}'s operator is of kind {tag}, and the formula's of kind {}",
                self.tag()
            )));
        }
        match self {
            Op::Expr | Op::Copy => {}
            Op::Cmp(d) | Op::Constant(_, d) | Op::Not(d) => *d = Dedup::load(r)?,
            Op::Merge(m) => m.load(r)?,
            Op::Win(win) => win.load(r)?,
            Op::Since(s) => s.load(r)?,
            Op::Bounded(p) => {
                let (a, b) = (p.1.a(), p.1.b());
                p.0 = Pieces::load(r)?;
                p.1 = BoundedUntil::load(r, a, b)?;
            }
            Op::Until(u) => u.load(r)?,
        }
        Ok(())
    }
}

/// The formula's fingerprint: a saved state is only read back by the formula that saved
/// it.
fn fingerprint(formula: &DenseFormula) -> u64 {
    saved::fnv(format!("{formula:?}").as_bytes()) // not a message: a fingerprint
}

impl DenseMonitor {
    /// The monitor's state as plain data: bytes that [`DenseMonitor::load`] reads back into
    /// a monitor that continues exactly where this one is (the same change points, bit for
    /// bit). They hold the last row, every operator's pieces and deques (a window's worth
    /// each), and the change points decided but not yet given.
    pub fn save(&self) -> Vec<u8> {
        let mut w = Writer::default();
        w.word(saved::MAGIC);
        w.word(saved::VERSION);
        w.word(fingerprint(&self.formula));
        w.count(self.vars);
        w.count(self.ops.len());
        w.f64(self.t0);
        w.f64(self.x);
        w.count(self.rows.len());
        w.opt_i128(self.rows.origin());
        w.opt_i128(self.rows.last_int());
        if !self.t0.is_nan() {
            let (_, columns) = self.rows.rows();
            for c in columns {
                w.f64(c.last().copied().unwrap_or(f64::NAN));
            }
        }
        for &f in &self.front {
            w.f64(f);
        }
        w.points(self.held.iter());
        for op in &self.ops {
            op.save(&mut w);
        }
        let sum = saved::fnv(&w.bytes);
        w.word(sum);
        w.bytes
    }

    /// The monitor [`DenseMonitor::save`] saved, for `formula` over `vars` variables (the
    /// same as the saved monitor's). The bytes end with a checksum, so bytes cut short or
    /// changed are refused; then every field is checked, so that bytes changed on purpose
    /// and summed again ([`resum`](super::super::saved::resum)) are refused too when they are no state a
    /// monitor could have reached (from another formula, sizes beyond the bytes given,
    /// NaN, times that do not increase, indices out of range, deques and folds that are not
    /// those of their pieces); what no check can tell (one value changed for another) still
    /// never makes the monitor panic.
    pub fn load(
        formula: &DenseFormula,
        vars: usize,
        bytes: &[u8],
    ) -> Result<DenseMonitor, SavedStateError> {
        let mut m = DenseMonitor::new(formula, vars)
            .map_err(|e| SavedStateError { message: e.to_string() })?;
        if bytes.get(..8).is_none_or(|w| w != saved::MAGIC.to_le_bytes()) {
            return Err(SavedStateError {
                message: "the bytes are no saved dense-time monitor (they do not start with \
                          `hstldns1`)"
                    .to_string(),
            });
        }
        let body = bytes.len().saturating_sub(8);
        if bytes.len() < 16
            || !bytes.len().is_multiple_of(8)
            || saved::sum_of(bytes) != saved::fnv(&bytes[..body])
        {
            return Err(SavedStateError {
                message: format!(
                    "the state's checksum does not match its {} bytes: they were cut short or \
                     changed",
                    bytes.len()
                ),
            });
        }
        let mut r = Reader::new(&bytes[..body]);
        r.word("the header")?;
        let version = r.word("the version")?;
        if version != saved::VERSION {
            return Err(r.bad(&format!(
                "the state is of version {version}, and this monitor reads version {}",
                saved::VERSION
            )));
        }
        if r.word("the formula's fingerprint")? != fingerprint(formula) {
            return Err(r.bad("the state was saved by a monitor of another formula"));
        }
        let saved_vars = r.word("the variable count")?;
        let nodes = r.word("the node count")?;
        if saved_vars != vars as u64 || nodes != m.ops.len() as u64 {
            return Err(r.bad(&format!(
                "the state is for {saved_vars} variables and {nodes} nodes, and the monitor \
                 has {vars} and {}",
                m.ops.len()
            )));
        }
        let t0 = r.f64("the first stamp")?;
        let x = r.f64("the last stamp")?;
        let rows = r.index(usize::MAX >> 2, "the row count")?;
        let origin = r.opt_i128("the first whole-number stamp")?;
        let last_int = r.opt_i128("the last whole-number stamp")?;
        if t0.is_nan() && x.is_nan() {
            if rows != 0 || origin.is_some() || last_int.is_some() {
                return Err(r.bad("the state has rows but no first stamp"));
            }
        } else {
            if !(t0.is_finite() && x.is_finite() && t0 <= x && rows >= 1) {
                return Err(r.bad(&format!(
                    "the first stamp {t0} and the last {x} are not finite stamps in order"
                )));
            }
            match (origin, last_int) {
                (None, None) => {}
                (Some(o), Some(l)) => {
                    // Whole-number stamps: the first is 0 from the origin, the last exactly
                    // `l - o` after it.
                    let exact = l >= o && trace::relative(0, l, o).is_ok_and(|t| t == x);
                    if t0 != 0.0 || !exact || (rows == 1 && l != o) {
                        return Err(r.bad(&format!(
                            "the whole-number stamps {o} (first) and {l} (last) do not give \
                             the times {t0} and {x}"
                        )));
                    }
                }
                _ => return Err(r.bad("the state has a first whole-number stamp without a last")),
            }
            if rows == 1 && t0 != x {
                return Err(r.bad("one row, but its first and last stamps differ"));
            }
            let mut values = Vec::with_capacity(vars);
            for _ in 0..vars {
                values.push(r.value("the last row's values")?);
            }
            m.rows = DenseTraceBuilder::resumed(rows, x, &values, origin, last_int);
        }
        m.t0 = t0;
        m.x = x;
        for f in &mut m.front {
            *f = r.value("an operator's frontier")?;
        }
        let held = r.points("the decided change points")?;
        if held.first().is_some_and(|&(t, _)| t <= x || x.is_nan()) {
            return Err(r.bad("a decided change point comes no later than the last stamp"));
        }
        m.held = held.into();
        for (i, op) in m.ops.iter_mut().enumerate() {
            op.load(&mut r, i)?;
        }
        r.finish()?;
        Ok(m)
    }
}
