//! Per-particle random streams derived from (seed, ParticleId) (docs/architecture.md §3, determinism).
//!
//! The 256-bit xoshiro256++ state is filled from SplitMix64 seeded with a mix of the run seed
//! and the particle id (the seeding the xoshiro authors recommend), so stream k does not depend
//! on how many other particles exist or in which order they are created, and building N streams
//! costs O(N).

use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

/// SplitMix64 step (Steele, Lea, Flood 2014).
#[inline]
pub fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The stream of `stream` (a particle id, or a reserved id for driver-level randomness)
/// in a run with `seed`.
///
/// ```
/// use magsep_systems::rng::particle_stream;
/// use rand::RngExt;
/// let mut a = particle_stream(1, 7);
/// let mut b = particle_stream(1, 7);
/// assert_eq!(a.random::<u64>(), b.random::<u64>());
/// assert_ne!(particle_stream(1, 8).random::<u64>(), particle_stream(1, 7).random::<u64>());
/// ```
pub fn particle_stream(seed: u64, stream: u64) -> Xoshiro256PlusPlus {
    let mut mix = stream.wrapping_mul(0xD1B5_4A32_D192_ED03);
    let mut sm = seed ^ splitmix64(&mut mix);
    let mut bytes = [0u8; 32];
    for chunk in bytes.chunks_mut(8) {
        chunk.copy_from_slice(&splitmix64(&mut sm).to_le_bytes());
    }
    Xoshiro256PlusPlus::from_seed(bytes)
}

/// Stream id reserved for the packing driver (shuffles of the sweep order).
pub const DRIVER_STREAM: u64 = u64::MAX;

/// The four state words of a xoshiro256++ generator (for lossless recording).
///
/// ```
/// use magsep_systems::rng::{particle_stream, rng_from_state_words, rng_state_words};
/// let g = particle_stream(3, 4);
/// assert_eq!(rng_from_state_words(rng_state_words(&g)), g);
/// ```
pub fn rng_state_words(rng: &Xoshiro256PlusPlus) -> [u64; 4] {
    #[derive(serde::Deserialize)]
    struct Words {
        s: [u64; 4],
    }
    // The generator's serde form is {"s": [u64; 4]}: the same words `from_seed` reads.
    let v = serde_json::to_value(rng).expect("xoshiro state serializes");
    serde_json::from_value::<Words>(v)
        .expect("xoshiro state has four words")
        .s
}

/// Rebuild a generator from [`rng_state_words`].
pub fn rng_from_state_words(words: [u64; 4]) -> Xoshiro256PlusPlus {
    let mut bytes = [0u8; 32];
    for (i, w) in words.iter().enumerate() {
        bytes[i * 8..i * 8 + 8].copy_from_slice(&w.to_le_bytes());
    }
    Xoshiro256PlusPlus::from_seed(bytes)
}
