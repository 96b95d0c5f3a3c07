//! A doubling chain of 24 lets through `hstl!` (issue 11, class 1): as a tree it would have
//! 2^23 atoms (and took rustc 75 s); the lets are shared, so it compiles as fast as any
//! small spec, and every monitor gives the values of the one atom it equals.

use hstl::robustness::{Trace, offline};

hstl::hstl! {
    /// 24 lets, each the last one twice.
    spec Doubling {
        state { x: int in 0..=14, y: int in 0..=14 }
        let L0 = x > 3 && y < 9;
        let L1 = L0 && L0;
        let L2 = L1 && L1;
        let L3 = L2 && L2;
        let L4 = L3 && L3;
        let L5 = L4 && L4;
        let L6 = L5 && L5;
        let L7 = L6 && L6;
        let L8 = L7 && L7;
        let L9 = L8 && L8;
        let L10 = L9 && L9;
        let L11 = L10 && L10;
        let L12 = L11 && L11;
        let L13 = L12 && L12;
        let L14 = L13 && L13;
        let L15 = L14 && L14;
        let L16 = L15 && L15;
        let L17 = L16 && L16;
        let L18 = L17 && L17;
        let L19 = L18 && L18;
        let L20 = L19 && L19;
        let L21 = L20 && L20;
        let L22 = L21 && L21;
        let L23 = L22 && L22;
        let Soon = eventually[0..=3] L23;
        let Both = Soon && always[0..=2] L23 && Soon;
        task always[0..=5] L23 && Both;
    }
    /// What the chain equals.
    spec Plain {
        state { x: int in 0..=14, y: int in 0..=14 }
        let L23 = x > 3 && y < 9;
        let Soon = eventually[0..=3] L23;
        let Both = Soon && always[0..=2] L23 && Soon;
        task always[0..=5] L23 && Both;
    }
}

#[test]
fn a_doubling_chain_compiles_and_monitors() {
    let states: Vec<doubling::State> =
        (0..200i64).map(|t| doubling::State { x: (t * 7) % 15, y: (t * 11) % 15 }).collect();
    let plain: Vec<plain::State> = states.iter().map(|s| plain::State { x: s.x, y: s.y }).collect();
    assert_eq!(doubling::task::signal(&states), plain::task::signal(&plain));
    assert_eq!(doubling::lets::both::signal(&states), plain::lets::both::signal(&plain));
    assert_eq!(doubling::lets::l23::at(&states[3]), plain::lets::l23::at(&plain[3]));
    assert_eq!(doubling::task::robustness(&states), plain::task::robustness(&plain));
    // The formula is a few dozen nodes (as a tree, 2^23 atoms), and the runtime's
    // evaluator agrees.
    let f = doubling::task::formula();
    assert!(f.len() < 40, "{} nodes", f.len());
    assert!(f.tree_len() > 1 << 23);
    let columns = vec![
        states.iter().map(|s| s.x as f64).collect(),
        states.iter().map(|s| s.y as f64).collect(),
    ];
    let trace = Trace::from_columns(columns).expect("two columns");
    assert_eq!(offline::signal(&f, &trace), doubling::task::signal(&states));
    let mut online = doubling::task::Online::new();
    let mut values: Vec<f64> =
        states.iter().filter_map(|s| online.push(s)).map(|v| v.value).collect();
    values.extend(online.finish().iter().map(|v| v.value));
    assert_eq!(values, plain::task::signal(&plain));
}
