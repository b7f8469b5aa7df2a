//! One deterministic random stream per work unit: the random numbers of every dnnevo crate.
//!
//! Every random draw in an evolution run comes from a [`Stream`] derived from the tuple
//! `(seed, generation, purpose, individual, trial)`, never from a thread-local or global generator.
//! A work unit (one child, one individual's initial genome, one trial) owns its stream, so a run
//! gives the same bits for any number of threads or machines, and any work unit can be replayed on
//! its own.
//!
//! The generator is our own so that results never change with a dependency:
//!
//! - the tuple is hashed into one 64-bit word: each of the five words is pre-mixed with its own
//!   constant and folded in with the SplitMix64 finalizer, so tuples that differ in one bit of one
//!   field give unrelated hashes;
//! - that word seeds SplitMix64, whose first four outputs are the state of xoshiro256++
//!   (Blackman & Vigna), the generator behind [`Stream::next_u64`].
//!
//! # Example
//! ```
//! use streams::{Purpose, Stream};
//! let mut a = Stream::new(42, 3, Purpose::Reproduce, 7, 0);
//! let mut b = Stream::new(42, 3, Purpose::Reproduce, 7, 0);
//! assert_eq!(a.next_u64(), b.next_u64());
//! let u = a.uniform();
//! assert!((0.0..1.0).contains(&u));
//! ```

// Internals for the crate's own integration tests (tests/unit); not public API.
#[doc(hidden)]
pub mod testing;

/// What a stream is used for; part of the tuple a stream is derived from.
///
/// The codes returned by [`Purpose::code`] enter the hash and are therefore part of the file of
/// every saved run: they are stable and must never be renumbered. New purposes get new codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Purpose {
    /// Drawing the initial population (code 1).
    Init,
    /// Building one child of the next generation: selection, crossover, mutation (code 2).
    Reproduce,
    /// Randomness inside one trial of a task, such as a start position (code 3).
    Trial,
    /// Seeding a population from evolved networks (code 4).
    Seeding,
    /// Randomness of an evaluation outside evolution, such as a test run (code 5).
    Evaluate,
    /// A run's validation set: fresh conditions, fixed for the whole run, on which the best
    /// candidates of each generation are re-scored to pick the champion (code 6).
    Validate,
}

impl Purpose {
    /// The stable code of this purpose: Init 1, Reproduce 2, Trial 3, Seeding 4, Evaluate 5,
    /// Validate 6.
    pub fn code(self) -> u64 {
        match self {
            Purpose::Init => 1,
            Purpose::Reproduce => 2,
            Purpose::Trial => 3,
            Purpose::Seeding => 4,
            Purpose::Evaluate => 5,
            Purpose::Validate => 6,
        }
    }
}

/// The golden-ratio increment of SplitMix64.
const GOLDEN: u64 = 0x9e37_79b9_7f4a_7c15;

/// The SplitMix64 output function (a bijection of u64 with full avalanche).
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// SplitMix64: a tiny generator used only to expand one hashed word into a xoshiro state.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(GOLDEN);
        mix64(self.0)
    }
}

/// Hashes the five words of a stream's tuple into one seed word.
fn hash_tuple(words: [u64; 5]) -> u64 {
    // A fixed, arbitrary starting value, so that the all-zero tuple is not special.
    let mut h: u64 = 0x6a09_e667_f3bc_c908;
    for (k, &w) in words.iter().enumerate() {
        // Each position has its own offset, so swapping two fields changes the hash.
        let lane = GOLDEN.wrapping_mul(k as u64 + 1);
        h = mix64(h ^ mix64(w.wrapping_add(lane)));
    }
    h
}

/// A xoshiro256++ random stream for one work unit.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Stream {
    s: [u64; 4],
}

impl Stream {
    /// The stream of the work unit `(seed, generation, purpose, individual, trial)`.
    ///
    /// Use 0 for fields that do not apply (for example `trial` when building a child).
    pub fn new(seed: u64, generation: u64, purpose: Purpose, individual: u64, trial: u64) -> Self {
        let h = hash_tuple([seed, generation, purpose.code(), individual, trial]);
        let mut sm = SplitMix64(h);
        let s = [sm.next(), sm.next(), sm.next(), sm.next()];
        // SplitMix64 is a bijection on distinct counters, so the four words are never all zero
        // (they come from four distinct counter values, at most one of which maps to 0).
        Stream { s }
    }

    /// A stream with a raw xoshiro256++ state, for checking against the reference vectors.
    pub(crate) fn from_state(s: [u64; 4]) -> Self {
        Stream { s }
    }

    /// The next 64 random bits (xoshiro256++).
    pub fn next_u64(&mut self) -> u64 {
        let s = &mut self.s;
        let result = s[0].wrapping_add(s[3]).rotate_left(23).wrapping_add(s[0]);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        result
    }

    /// A uniform float in [0, 1) with 53 random bits (a multiple of 2^-53).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// `lo + (hi - lo) * u` with `u` from [`Stream::uniform`]: uniform over [lo, hi) when lo < hi.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// A uniform integer in `0..n`, without modulo bias (Lemire's multiply-and-reject).
    ///
    /// # Panics
    /// If `n == 0`.
    pub fn below(&mut self, n: u64) -> u64 {
        assert!(n >= 1, "Stream::below needs n >= 1");
        // 2^64 mod n: products whose low word falls below it are rejected.
        let threshold = n.wrapping_neg() % n;
        loop {
            let m = u128::from(self.next_u64()) * u128::from(n);
            if (m as u64) >= threshold {
                return (m >> 64) as u64;
            }
        }
    }

    /// A uniform integer in `lo..=hi`.
    ///
    /// # Panics
    /// If `lo > hi`.
    pub fn range_inclusive_int(&mut self, lo: u64, hi: u64) -> u64 {
        assert!(lo <= hi, "Stream::range_inclusive_int needs lo <= hi");
        match (hi - lo).checked_add(1) {
            Some(n) => lo + self.below(n),
            None => self.next_u64(), // the whole u64 range
        }
    }

    /// True with probability `p` (`uniform() < p`): never for p <= 0, always for p >= 1.
    pub fn bernoulli(&mut self, p: f64) -> bool {
        self.uniform() < p
    }

    /// A standard normal variate (Box–Muller, using two uniforms per call and the cosine branch).
    ///
    /// Deterministic for a given stream; `ln` and `cos` come from the platform's math library, so
    /// the last bit may differ between platforms. The paper's GA does not use it.
    pub fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform(); // (0, 1], so ln is finite
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}
