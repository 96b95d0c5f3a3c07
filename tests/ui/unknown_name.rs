use hstl_macros::hstl;

hstl! {
    spec Unknown {
        state { x: int in 0..=3 }
        let A = x > 1;
        task always[0..] (A && eventually[0..5] Goal);
    }
}

fn main() {}
