//! The limits of the finite-domain pass, which the checker and the lints both honour.

/// The finite-domain checks enumerate at most this many states.
pub const MAX_DOMAIN_STATES: u64 = 1_000_000;

/// The finite-domain checks evaluate at most this many formulas (states times the
/// formulas and lets evaluated per state).
pub const MAX_DOMAIN_WORK: u64 = 20_000_000;
