use hstl_macros::hstl;

hstl! {
    spec Twice {
        state { x: int in 0..=3 }
        let A = x > 1;
        let A = x < 2;
        task always A;
    }
}

fn main() {}
