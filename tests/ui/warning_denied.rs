#![deny(warnings)]

use hstl_macros::hstl;

hstl! {
    spec Unused {
        state { x: float }
        let A = x > 1;
        let Spare = x < 0;
        task eventually[0..10] A;
    }
}

fn main() {}
