//! The fuzz targets' properties (`fuzz/props/`) in every test run: each target's committed
//! corpus replayed, then a fixed number of seeded mutations of it (bytes flipped, inserted,
//! deleted, duplicated, two entries spliced). A bounded smoke of seconds, so that a change
//! that breaks a property, or an input libFuzzer once found, fails `cargo test` without the
//! nightly toolchain; the long coverage-guided runs are `cargo fuzz` (fuzz/README.md).

use std::path::{Path, PathBuf};

use hstl::runtime::{RngExt, seeded_rng};

#[path = "../../fuzz/props/check.rs"]
mod check;
#[path = "../../fuzz/props/format.rs"]
mod format;
#[path = "../../fuzz/props/lsp_frames.rs"]
mod lsp_frames;
#[path = "../../fuzz/props/lsp_session.rs"]
mod lsp_session;
#[path = "../../fuzz/props/policy.rs"]
mod policy;
#[path = "../../fuzz/props/trace_csv.rs"]
mod trace_csv;
#[path = "../../fuzz/props/world.rs"]
mod world;

/// Mutations per target: a few seconds for all of them in a debug build.
const MUTATIONS: usize = 150;
/// Inputs longer than this are not mutated (a policy's Q-tables are long and slow to replay).
const MAX_MUTATED_LEN: usize = 16 << 10;

fn corpus(target: &str) -> Vec<Vec<u8>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/corpus").join(target);
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("entry").path())
        .filter(|p| p.is_file())
        .collect();
    paths.sort();
    assert!(!paths.is_empty(), "{} has no seeds", dir.display());
    paths.iter().map(|p| std::fs::read(p).expect("read a seed")).collect()
}

/// One mutation of `seeds[i]`, drawn from `rng`.
fn mutate(seeds: &[Vec<u8>], rng: &mut hstl::runtime::Rng) -> Vec<u8> {
    let small: Vec<&Vec<u8>> = seeds.iter().filter(|s| s.len() <= MAX_MUTATED_LEN).collect();
    let pick = |rng: &mut hstl::runtime::Rng| small[rng.random_range(0..small.len())].clone();
    let mut data = pick(rng);
    for _ in 0..rng.random_range(1..4) {
        let len = data.len();
        match rng.random_range(0..6) {
            0 if len > 0 => {
                let i = rng.random_range(0..len);
                data[i] ^= 1 << rng.random_range(0..8);
            }
            1 => {
                let i = rng.random_range(0..=len);
                let byte = *[b'\n', b';', b'{', b'}', b'[', b'"', b',', 0xff, b'0', b'.']
                    .get(rng.random_range(0..10))
                    .expect("in range");
                data.insert(i, byte);
            }
            2 if len > 0 => {
                let i = rng.random_range(0..len);
                let j = rng.random_range(i..=len.min(i + 16));
                data.drain(i..j);
            }
            3 if len > 0 => {
                let i = rng.random_range(0..len);
                let j = rng.random_range(i..=len.min(i + 32));
                let chunk = data[i..j].to_vec();
                data.splice(j..j, chunk);
            }
            4 => {
                let other = pick(rng);
                let cut = rng.random_range(0..=data.len());
                let from = rng.random_range(0..=other.len());
                data.truncate(cut);
                data.extend_from_slice(&other[from..]);
            }
            _ => data.truncate(rng.random_range(0..=len)),
        }
    }
    data
}

fn smoke(target: &str, property: fn(&[u8])) {
    let seeds = corpus(target);
    for seed in &seeds {
        property(seed);
    }
    let mut rng = seeded_rng(0x5eed ^ target.len() as u64);
    for _ in 0..MUTATIONS {
        property(&mutate(&seeds, &mut rng));
    }
}

#[test]
fn check_target() {
    smoke("check", check::check);
}

#[test]
fn format_target() {
    smoke("format", format::check);
}

#[test]
fn lsp_frames_target() {
    smoke("lsp_frames", lsp_frames::check);
}

#[test]
fn lsp_session_target() {
    smoke("lsp_session", lsp_session::check);
}

#[test]
fn policy_target() {
    smoke("policy", policy::check);
}

#[test]
fn trace_csv_target() {
    smoke("trace_csv", trace_csv::check);
}

#[test]
fn world_target() {
    smoke("world", world::check);
}
