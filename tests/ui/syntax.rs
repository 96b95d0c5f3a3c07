use hstl_macros::hstl;

hstl! {
    spec Broken {
        state { x: int in 0..=3 }
        let A = x > ;
        task always A;
    }
}

fn main() {}
