use hstl_macros::hstl;

hstl! {
    spec Reach {
        state { x: int in 0..=3 }
        let A = x > 1;
        task always[0..] eventually[0..4] A;
        option A { reach: eventually[0..3] A, terminate: A }
    }
}

fn main() {}
