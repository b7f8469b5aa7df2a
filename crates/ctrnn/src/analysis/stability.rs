//! Eigenvalues of a Jacobian and the stability class they give an equilibrium.

use nalgebra::linalg::Schur;
use nalgebra::DMatrix;
use serde::Serialize;

use crate::error::{Error, Result};

/// Real parts within this distance of 0 (relative to the largest eigenvalue modulus, and at least
/// this absolutely) count as 0: the equilibrium is then [`Stability::NonHyperbolic`].
pub const MARGINAL: f64 = 1e-9;

/// The stability class of an equilibrium, from the eigenvalues of its Jacobian.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stability {
    /// Every eigenvalue real and negative: nearby states approach without turning.
    StableNode,
    /// Every real part negative, some eigenvalues complex: nearby states spiral in.
    StableFocus,
    /// Some real parts negative and some positive: attracting along some directions only.
    Saddle,
    /// Every eigenvalue real and positive.
    UnstableNode,
    /// Every real part positive, some eigenvalues complex: nearby states spiral out.
    UnstableFocus,
    /// Some real part is 0 (within [`MARGINAL`]): linearisation does not decide, as at a fold or a
    /// Hopf point.
    NonHyperbolic,
}

impl Stability {
    /// Every class, in declaration order.
    pub const ALL: [Stability; 6] = [
        Stability::StableNode,
        Stability::StableFocus,
        Stability::Saddle,
        Stability::UnstableNode,
        Stability::UnstableFocus,
        Stability::NonHyperbolic,
    ];

    /// Classifies eigenvalues given as `[re, im]` pairs.
    ///
    /// # Example
    /// ```
    /// use ctrnn::analysis::Stability;
    /// assert_eq!(Stability::classify(&[[-1.0, 0.0], [-2.0, 0.0]]), Stability::StableNode);
    /// assert_eq!(Stability::classify(&[[-1.0, 2.0], [-1.0, -2.0]]), Stability::StableFocus);
    /// assert_eq!(Stability::classify(&[[1.0, 0.0], [-2.0, 0.0]]), Stability::Saddle);
    /// assert_eq!(Stability::classify(&[[0.5, 1.0], [0.5, -1.0]]), Stability::UnstableFocus);
    /// ```
    pub fn classify(eigenvalues: &[[f64; 2]]) -> Stability {
        let scale = eigenvalues
            .iter()
            .map(|[re, im]| re.hypot(*im))
            .fold(1.0, f64::max);
        let eps = MARGINAL * scale;
        let complex = eigenvalues.iter().any(|[_, im]| im.abs() > eps);
        let neg = eigenvalues.iter().filter(|[re, _]| *re < -eps).count();
        let pos = eigenvalues.iter().filter(|[re, _]| *re > eps).count();
        match (neg, pos) {
            _ if neg + pos < eigenvalues.len() => Stability::NonHyperbolic,
            (_, 0) if complex => Stability::StableFocus,
            (_, 0) => Stability::StableNode,
            (0, _) if complex => Stability::UnstableFocus,
            (0, _) => Stability::UnstableNode,
            _ => Stability::Saddle,
        }
    }

    /// Whether nearby states approach the equilibrium (a stable node or focus).
    pub fn is_stable(self) -> bool {
        matches!(self, Stability::StableNode | Stability::StableFocus)
    }
}

/// The eigenvalues of a square matrix as `[re, im]` pairs, sorted by real part, largest first
/// (then by imaginary part, positive first).
pub fn eigenvalues(m: DMatrix<f64>) -> Result<Vec<[f64; 2]>> {
    let n = m.nrows();
    let schur = Schur::try_new(m, f64::EPSILON, 1000 * n.max(1)).ok_or_else(|| {
        Error::InvalidArgument(
            "the eigenvalue iteration did not converge; the Jacobian may hold extreme values"
                .into(),
        )
    })?;
    let mut ev: Vec<[f64; 2]> = schur
        .complex_eigenvalues()
        .iter()
        .map(|z| [z.re, z.im])
        .collect();
    ev.sort_by(|a, b| b[0].total_cmp(&a[0]).then(b[1].total_cmp(&a[1])));
    Ok(ev)
}

/// The slowest time scale of the linearisation, `1 / min |Re lambda|`: how long the slowest
/// direction takes to grow or decay by a factor e. None when some real part is 0.
pub(crate) fn time_scale(eigenvalues: &[[f64; 2]]) -> Option<f64> {
    let slowest = eigenvalues
        .iter()
        .map(|[re, _]| re.abs())
        .fold(f64::INFINITY, f64::min);
    (slowest > 0.0 && slowest.is_finite()).then(|| 1.0 / slowest)
}
