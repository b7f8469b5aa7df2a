//! The modular genome (paper §2.2): a network's parameters as one flat vector of model units.
//!
//! A network of N neurons and M sensors has `N * (2 + M + N)` genes, one indivisible block of
//! `2 + M + N` genes per neuron. Neuron i's block is, in order:
//!
//! ```text
//! tau_i, theta_i, sensor_weights[i][0..M], weights[i][0..N]
//! ```
//!
//! where `weights[i][j]` is the weight from neuron j to neuron i, so a block holds the neuron's
//! time constant, its threshold, and everything that flows into it. Gene g belongs to neuron
//! `g / (2 + M + N)`. This is the layout of the genomes that ask/tell hands out and takes back, and
//! crossover cuts only between blocks.
//!
//! Genes are stored in model units (no scaling to [0, 1]); [`Ranges`] only bounds the initial draw
//! and mutation.
//!
//! # Example
//! ```
//! use ctrnn::genome::{decode, encode, random, Layout, Ranges};
//! use ctrnn::rng::{Purpose, Stream};
//! let layout = Layout { size: 3, n_inputs: 1 };
//! let mut stream = Stream::new(1, 0, Purpose::Init, 0, 0);
//! let genes = random(layout, &Ranges::default(), &mut stream);
//! assert_eq!(genes.len(), layout.len()); // 3 x (2 + 1 + 3) = 18
//! let net = decode(layout, &genes)?;
//! assert_eq!(encode(&net), genes);
//! # Ok::<(), ctrnn::Error>(())
//! ```

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::network::Network;
use crate::rng::Stream;

/// The intervals that the initial population is drawn from and that mutation resamples over.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Ranges {
    /// Time constants `(lo, hi)`, with `lo > 0`. Default `(0.5, 10.0)`.
    pub tau: (f64, f64),
    /// Thresholds `(lo, hi)`. Default `(-16.0, 16.0)`.
    pub theta: (f64, f64),
    /// Recurrent weights `(lo, hi)`. Default `(-16.0, 16.0)`.
    pub weights: (f64, f64),
    /// Sensor weights `(lo, hi)`. Default `(-16.0, 16.0)`.
    pub sensor_weights: (f64, f64),
}

impl Default for Ranges {
    fn default() -> Self {
        Ranges {
            tau: (0.5, 10.0),
            theta: (-16.0, 16.0),
            weights: (-16.0, 16.0),
            sensor_weights: (-16.0, 16.0),
        }
    }
}

impl Ranges {
    /// Checks every interval: finite bounds with `lo < hi`, and `tau`'s `lo > 0`.
    ///
    /// # Example
    /// ```
    /// use ctrnn::genome::Ranges;
    /// let bad = Ranges { theta: (1.0, -1.0), ..Ranges::default() };
    /// assert!(bad.validate().unwrap_err().to_string().contains("ranges.theta"));
    /// ```
    pub fn validate(&self) -> Result<()> {
        for (name, (lo, hi)) in [
            ("tau", self.tau),
            ("theta", self.theta),
            ("weights", self.weights),
            ("sensor_weights", self.sensor_weights),
        ] {
            if !(lo.is_finite() && hi.is_finite()) {
                return Err(Error::Config(format!(
                    "ranges.{name} is ({lo}, {hi}); both bounds must be finite"
                )));
            }
            if lo >= hi {
                return Err(Error::Config(format!(
                    "ranges.{name} is ({lo}, {hi}); the lower bound must be below the upper bound"
                )));
            }
            if !(hi - lo).is_finite() {
                // A draw lo + u (hi - lo), or a mutation's step, would be infinite.
                return Err(Error::Config(format!(
                    "ranges.{name} is ({lo:e}, {hi:e}); its width overflows: the bounds must be \
                     less than {:e} apart",
                    f64::MAX
                )));
            }
        }
        if self.tau.0 <= 0.0 {
            return Err(Error::Config(format!(
                "ranges.tau is ({}, {}); time constants must be > 0, so the lower bound must be > 0",
                self.tau.0, self.tau.1
            )));
        }
        Ok(())
    }
}

/// The most parameters (genes) one network may have: 2^26, 512 MiB of `f64`, so a size of up to
/// about 8,000 neurons. A 1 GB network file holds about 2^26 numbers as text; larger requests
/// are typing errors, refused before any allocation.
pub const MAX_GENES: usize = 1 << 26;

/// `bytes` in readable units (`None` is beyond any machine).
pub fn bytes(bytes: Option<f64>) -> String {
    let Some(b) = bytes else {
        return "more than 16 EiB".into();
    };
    let units = ["bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut x = b;
    let mut u = 0;
    while x >= 1024.0 && u + 1 < units.len() {
        x /= 1024.0;
        u += 1;
    }
    format!("{x:.1} {}", units[u])
}

/// The shape of a genome: N neurons and M sensors.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Layout {
    /// Number of neurons N (at least 1).
    pub size: usize,
    /// Number of sensors M (may be 0).
    pub n_inputs: usize,
}

impl Layout {
    /// The layout of an existing network.
    pub fn of(net: &Network) -> Layout {
        Layout {
            size: net.size(),
            n_inputs: net.n_inputs(),
        }
    }

    /// Genes in one neuron's block: `2 + M + N`.
    pub fn genes_per_neuron(&self) -> usize {
        2 + self.n_inputs + self.size
    }

    /// Genes in the whole genome: `N * (2 + M + N)`.
    #[allow(clippy::len_without_is_empty)]
    pub fn len(&self) -> usize {
        self.size * self.genes_per_neuron()
    }

    /// Checks that the layout has at least one neuron and at most [`MAX_GENES`] genes, before
    /// anything is allocated (so a huge size is an error, never an abort).
    pub fn validate(&self) -> Result<()> {
        if self.size == 0 {
            return Err(Error::Config(
                "layout.size is 0; a network needs at least 1 neuron".into(),
            ));
        }
        let genes = self
            .n_inputs
            .checked_add(self.size)
            .and_then(|n| n.checked_add(2))
            .and_then(|n| n.checked_mul(self.size));
        match genes {
            Some(g) if g <= MAX_GENES => Ok(()),
            _ => Err(Error::Config(format!(
                "a network of size {} with {} has {} parameters ({}); the limit is {MAX_GENES} \
                 parameters (512 MiB)",
                self.size,
                crate::error::counted(self.n_inputs, "input"),
                genes.map_or("more than 2^64".to_string(), |g| g.to_string()),
                bytes(genes.map(|g| g as f64 * 8.0)),
            ))),
        }
    }

    /// A readable name for gene `g`, such as `"gene 9 (neuron 1, weights[1][2])"`.
    ///
    /// # Panics
    /// If `g` is not a gene of the layout (`g >= self.len()`).
    pub fn gene_name(&self, g: usize) -> String {
        assert!(
            g < self.len(),
            "gene {g} of a layout of {} genes",
            self.len()
        );
        let per = self.genes_per_neuron();
        let (i, o) = (g / per, g % per);
        let what = match Gene::of(*self, o) {
            Gene::Tau => format!("tau[{i}]"),
            Gene::Theta => format!("theta[{i}]"),
            Gene::SensorWeight(k) => format!("sensor_weights[{i}][{k}]"),
            Gene::Weight(j) => format!("weights[{i}][{j}]"),
        };
        format!("gene {g} (neuron {i}, {what})")
    }
}

/// Which parameter a position inside a neuron's block holds.
enum Gene {
    Tau,
    Theta,
    SensorWeight(usize),
    Weight(usize),
}

impl Gene {
    /// The parameter at offset `o` (`0 <= o < 2 + M + N`) of a block.
    fn of(layout: Layout, o: usize) -> Gene {
        match o {
            0 => Gene::Tau,
            1 => Gene::Theta,
            o if o < 2 + layout.n_inputs => Gene::SensorWeight(o - 2),
            o => Gene::Weight(o - 2 - layout.n_inputs),
        }
    }
}

/// The genome of `net`, in the block order described in the module docs. The state is not encoded.
pub fn encode(net: &Network) -> Vec<f64> {
    let (n, m) = (net.size(), net.n_inputs());
    let mut genes = Vec::with_capacity(Layout::of(net).len());
    for i in 0..n {
        genes.push(net.tau()[i]);
        genes.push(net.theta()[i]);
        genes.extend_from_slice(&net.sensor_weights()[i * m..(i + 1) * m]);
        genes.extend_from_slice(&net.weights()[i * n..(i + 1) * n]);
    }
    genes
}

/// The network that `genes` encodes, with its state at zero; the exact inverse of [`encode`].
///
/// Errors name the offending gene and its neuron: a wrong length, a non-finite value, or a time
/// constant that is not positive.
pub fn decode(layout: Layout, genes: &[f64]) -> Result<Network> {
    check_genes(layout, genes)?;
    let (n, m, per) = (layout.size, layout.n_inputs, layout.genes_per_neuron());
    let mut tau = Vec::with_capacity(n);
    let mut theta = Vec::with_capacity(n);
    let mut sensor_weights = Vec::with_capacity(n * m);
    let mut weights = Vec::with_capacity(n * n);
    for block in genes.chunks_exact(per) {
        tau.push(block[0]);
        theta.push(block[1]);
        sensor_weights.extend_from_slice(&block[2..2 + m]);
        weights.extend_from_slice(&block[2 + m..]);
    }
    Network::new(tau, theta, weights, sensor_weights, None)
}

/// Checks that `genes` make a network of `layout` without making it: their count, every gene
/// finite and every time constant > 0, the checks of [`decode`] that a genome can fail (what
/// [`Network::new`] checks besides follows from them). No allocation, so a whole population is
/// checked cheaply.
pub fn check_genes(layout: Layout, genes: &[f64]) -> Result<()> {
    layout.validate()?;
    let (n, m, per) = (layout.size, layout.n_inputs, layout.genes_per_neuron());
    if genes.len() != layout.len() {
        return Err(Error::InvalidArgument(format!(
            "genome has {} genes; a network of N = {n} neurons and M = {m} sensors needs \
             N x (2 + M + N) = {}",
            genes.len(),
            layout.len()
        )));
    }
    if let Some(g) = genes.iter().position(|v| !v.is_finite()) {
        return Err(Error::InvalidNetwork(format!(
            "{} is {}; every gene must be finite",
            layout.gene_name(g),
            genes[g]
        )));
    }
    if let Some(i) = (0..n).find(|&i| genes[i * per] <= 0.0) {
        return Err(Error::InvalidNetwork(format!(
            "{} is {}; every time constant must be > 0",
            layout.gene_name(i * per),
            genes[i * per]
        )));
    }
    Ok(())
}

/// The interval `(lo, hi)` that gene `g` is drawn from and mutated over.
///
/// # Panics
/// If `g >= layout.len()`.
pub fn gene_range(layout: Layout, ranges: &Ranges, g: usize) -> (f64, f64) {
    assert!(
        g < layout.len(),
        "gene {g} is out of a genome of {} genes",
        layout.len()
    );
    match Gene::of(layout, g % layout.genes_per_neuron()) {
        Gene::Tau => ranges.tau,
        Gene::Theta => ranges.theta,
        Gene::SensorWeight(_) => ranges.sensor_weights,
        Gene::Weight(_) => ranges.weights,
    }
}

/// A random genome: each gene uniform over its range, drawn in gene order from `stream`.
pub fn random(layout: Layout, ranges: &Ranges, stream: &mut Stream) -> Vec<f64> {
    (0..layout.len())
        .map(|g| {
            let (lo, hi) = gene_range(layout, ranges, g);
            stream.range(lo, hi)
        })
        .collect()
}

/// Mutates `genes` in place: each gene, in order, is changed with probability `rate`, by
/// `mutation` (see [`Mutation`]). Returns how many genes were changed.
///
/// # Panics
/// If `genes.len() != layout.len()`.
pub fn mutate(
    layout: Layout,
    ranges: &Ranges,
    genes: &mut [f64],
    rate: f64,
    mutation: Mutation,
    stream: &mut Stream,
) -> usize {
    assert_eq!(
        genes.len(),
        layout.len(),
        "genome length does not match its layout"
    );
    let mut changed = 0;
    for (g, gene) in genes.iter_mut().enumerate() {
        if stream.bernoulli(rate) {
            let (lo, hi) = gene_range(layout, ranges, g);
            *gene = match mutation {
                Mutation::Uniform => stream.range(lo, hi),
                Mutation::Creep { scale } => {
                    reflect(*gene + scale * (hi - lo) * creep_step(stream), lo, hi)
                }
            };
            changed += 1;
        }
    }
    changed
}

/// How a mutated gene changes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mutation {
    /// Resampled uniformly over its range (the paper's).
    Uniform,
    /// Moved by `scale` times its range's width times a bell-shaped step of mean 0 and standard
    /// deviation 1 ([`creep_step`]), and reflected back into the range at its ends.
    Creep {
        /// The step's standard deviation as a fraction of the range's width, in (0, 1].
        scale: f64,
    },
}

/// A bell-shaped step of mean 0 and standard deviation 1: the sum of 12 uniform draws minus 6
/// (the Irwin-Hall approximation of the Gaussian, bounded at +-6). Sums alone, so every platform
/// gives the same bits, which a Gaussian through the math library's `ln` and `cos` would not.
pub fn creep_step(stream: &mut Stream) -> f64 {
    let mut sum = 0.0;
    for _ in 0..12 {
        sum += stream.uniform();
    }
    sum - 6.0
}

/// `x` folded into `[lo, hi]` by reflection at the ends (as often as needed).
pub(crate) fn reflect(x: f64, lo: f64, hi: f64) -> f64 {
    let width = hi - lo;
    let t = (x - lo).rem_euclid(2.0 * width);
    let folded = if t > width { 2.0 * width - t } else { t };
    (lo + folded).clamp(lo, hi)
}
