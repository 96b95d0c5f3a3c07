use hstl_macros::hstl;

hstl! {
    spec Window {
        state { x: float }
        let A = x > 1;
        task always[5..2] A && eventually[3..3] A && eventually[0..=2.5] A;
    }
}

fn main() {}
