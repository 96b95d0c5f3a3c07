//! The benchmark data: a random walk on the 15 x 15 grid world, shared by the benches and
//! the `walk` and `dense_walk` examples (which write it to CSV for the peers' script).

use hstl_robustness::{Bound, CmpOp, Expr, Formula, Interval, Trace};

/// Steps in the benchmark walk.
pub const STEPS: usize = 1_000_000;
/// The walk's seed.
pub const SEED: u64 = 0x5eed_2016;

/// splitmix64: small, fast, and easy to reproduce in any language.
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
}

/// `steps` states of a walk from (7, 7): each step Up, Down, Left or Right with equal
/// probability; a move off the grid (x, y in 0..=14) stays put.
pub fn walk(steps: usize, rng: &mut SplitMix64) -> Trace {
    let (mut x, mut y) = (7i64, 7i64);
    let mut xs = Vec::with_capacity(steps);
    let mut ys = Vec::with_capacity(steps);
    for _ in 0..steps {
        xs.push(x as f64);
        ys.push(y as f64);
        let (dx, dy) = match rng.next_u64() % 4 {
            0 => (0, 1),
            1 => (0, -1),
            2 => (-1, 0),
            _ => (1, 0),
        };
        if (0..=14).contains(&(x + dx)) && (0..=14).contains(&(y + dy)) {
            x += dx;
            y += dy;
        }
    }
    Trace::from_columns(vec![xs, ys]).expect("two columns of equal length")
}

/// Dense-time stamps for `steps` rows, in seconds: row `k` at the sum of `k` gaps of 1 to
/// 20 ms (uniform, drawn from `rng` after the walk), each the double nearest `ms / 1000`.
pub fn stamps(steps: usize, rng: &mut SplitMix64) -> Vec<f64> {
    let mut out = Vec::with_capacity(steps);
    let mut ms = 0u64;
    for _ in 0..steps {
        out.push(ms as f64 / 1000.0);
        ms += 1 + rng.next_u64() % 20;
    }
    out
}

fn cmp(lhs: Expr, op: CmpOp, rhs: Expr) -> Formula {
    Formula::cmp(lhs, op, rhs)
}

/// `lo_x < x < hi_x && lo_y < y < hi_y` over `x` (variable 0) and `y` (variable 1).
pub fn region(lo_x: f64, hi_x: f64, lo_y: f64, hi_y: f64) -> Formula {
    let (x, y, c) = (|| Expr::var(0), || Expr::var(1), Expr::constant);
    Formula::and(vec![
        cmp(x(), CmpOp::Gt, c(lo_x)),
        cmp(x(), CmpOp::Lt, c(hi_x)),
        cmp(y(), CmpOp::Gt, c(lo_y)),
        cmp(y(), CmpOp::Lt, c(hi_y)),
    ])
}

/// F1: `always[0..=w] (x > 3 && x < 9 && y > 10 && y < 14)`.
pub fn f1(w: usize) -> Formula {
    let i = Interval { start: 0, end: Bound::Inclusive(w) };
    Formula::always(i, region(3.0, 9.0, 10.0, 14.0))
}

/// F2: `always[0..] (eventually[0..40] A && eventually[0..40] B && eventually[0..40] C)`.
pub fn f2() -> Formula {
    let ev = |f| Formula::eventually(Interval { start: 0, end: Bound::Exclusive(40) }, f);
    let body = Formula::and(vec![
        ev(region(3.0, 9.0, 10.0, 14.0)),
        ev(region(1.0, 5.0, 1.0, 5.0)),
        ev(region(9.0, 13.0, 1.0, 7.0)),
    ]);
    Formula::always(Interval::ALL, body)
}

/// F3: `(x > 5) until[0..=20] (y > 10)`.
pub fn f3() -> Formula {
    Formula::until(
        Interval { start: 0, end: Bound::Inclusive(20) },
        cmp(Expr::var(0), CmpOp::Gt, Expr::constant(5.0)),
        cmp(Expr::var(1), CmpOp::Gt, Expr::constant(10.0)),
    )
}

/// P1, the past mirror of F1: `historically[0..=w] (x > 3 && x < 9 && y > 10 && y < 14)`.
pub fn p1(w: usize) -> Formula {
    let i = Interval { start: 0, end: Bound::Inclusive(w) };
    Formula::historically(i, region(3.0, 9.0, 10.0, 14.0))
}

/// P2, the past mirror of F2: every region held within the last 40 steps, at every step so
/// far: `historically[0..] (once[0..40] A && once[0..40] B && once[0..40] C)`.
pub fn p2() -> Formula {
    let once = |f| Formula::once(Interval { start: 0, end: Bound::Exclusive(40) }, f);
    let body = Formula::and(vec![
        once(region(3.0, 9.0, 10.0, 14.0)),
        once(region(1.0, 5.0, 1.0, 5.0)),
        once(region(9.0, 13.0, 1.0, 7.0)),
    ]);
    Formula::historically(Interval::ALL, body)
}

/// P3, the past mirror of F3: `(x > 5) since[0..=20] (y > 10)`.
pub fn p3() -> Formula {
    Formula::since(
        Interval { start: 0, end: Bound::Inclusive(20) },
        cmp(Expr::var(0), CmpOp::Gt, Expr::constant(5.0)),
        cmp(Expr::var(1), CmpOp::Gt, Expr::constant(10.0)),
    )
}
