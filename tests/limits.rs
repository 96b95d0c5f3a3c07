//! The front end refuses what the runtime would: where both hold a limit, it is one number.

#[test]
fn front_end_and_runtime_share_their_limits() {
    assert_eq!(hstl::lang::budget::MAX_WINDOW, hstl::runtime::memory::MAX_WINDOW as u64);
}
