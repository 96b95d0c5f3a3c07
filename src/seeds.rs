//! The seeds of a run's generators besides training's: each is the user's seed xor a named
//! offset, so that evaluating a policy or drawing its pictures never moves training's draws,
//! and every front end draws the same runs for the same seed.

/// The seed offset of the generator that draws the sample runs of the pictures.
pub const PICTURE_SEED: u64 = 0x9e37_79b9_7f4a_7c15;
/// The seed offset of the generator that draws the evaluation's starts after training.
pub const EVAL_SEED: u64 = 0x5eed;
