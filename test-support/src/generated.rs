//! What the generated-input tests share: their case counts and seeds from the environment,
//! and a proptest runner whose cases follow from one seed, so every machine (and every CI
//! run) checks the same cases and a count or bound they print can be reproduced.

use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

/// `name` from the environment as a number, or `default` when it is unset or not one.
pub fn env(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// A runner drawing its cases from ChaCha seeded with `seed` (its first eight bytes, little
/// endian, the rest zero), whatever `config.rng_seed` says.
pub fn seeded_runner(config: Config, seed: u64) -> TestRunner {
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &bytes);
    TestRunner::new_with_rng(config, rng)
}
