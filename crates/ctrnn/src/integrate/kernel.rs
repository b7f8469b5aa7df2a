//! The step itself, written once over the crate's lane vectors: one Euler or RK4 step of every
//! lane at once, as straight-line arithmetic over rows of `V`.

use crate::math::sigmoid_lanes;
use crate::vector::{Group, Vector};

use super::{Integrator, Method};

/// The arrays of one step, viewed as rows of the lane vector `V`: the parameters, the step sizes
/// and the work rows (everything but the state).
pub(super) struct Work<'a, V: Vector> {
    pub(super) theta: &'a [V::Row],
    pub(super) weights: &'a [V::Row],
    pub(super) sensor_weights: &'a [V::Row],
    /// `dt/tau`, its half and its sixth.
    pub(super) h: &'a [V::Row],
    pub(super) h2: &'a [V::Row],
    pub(super) h6: &'a [V::Row],
    /// `S I` for the current input row.
    pub(super) ext: &'a mut [V::Row],
    /// Firing rates.
    pub(super) out: &'a mut [V::Row],
    /// RK4's first three slopes (the fourth is used as soon as it is known).
    pub(super) k: [&'a mut [V::Row]; 3],
    /// The point where RK4's next slope is taken.
    pub(super) probe: &'a mut [V::Row],
}

impl<V: Vector> Work<'_, V> {
    /// Holds `inputs` for `integ.substeps` steps of the state `v`; without inputs, holds the
    /// sensor drive already in `ext`. With `fresh`, `out` already holds the firing rates of `v`
    /// and the first step starts from them.
    #[inline(always)]
    pub(super) fn step(
        &mut self,
        v: &mut [V::Row],
        inputs: Option<&[V::Row]>,
        integ: &Integrator,
        fresh: bool,
    ) {
        if let Some(inputs) = inputs {
            sensor_drive::<V>(self.sensor_weights, inputs, self.ext);
        }
        self.integrate(v, integ, fresh);
    }

    /// `integ.substeps` steps of the state `v` with the sensor drive in `ext`; `fresh` as for
    /// [`step`](Self::step).
    #[inline(always)]
    fn integrate(&mut self, v: &mut [V::Row], integ: &Integrator, fresh: bool) {
        for s in 0..integ.substeps {
            let fresh = fresh && s == 0;
            match integ.method {
                Method::Euler => self.euler_step(v, fresh),
                Method::Rk4 => self.rk4_step(v, fresh),
            }
        }
    }

    /// One Euler step: `v += h * (ext + W f(v - theta) - v)`; with `fresh`, `out` already holds
    /// `f(v - theta)`.
    #[inline(always)]
    fn euler_step(&mut self, v: &mut [V::Row], fresh: bool) {
        let h = self.h;
        if !fresh {
            rates::<V>(self.theta, v, self.out);
        }
        drive::<V>(
            self.weights,
            self.ext,
            self.out,
            #[inline(always)]
            |i, acc| {
                let x = V::load(&v[i]);
                V::load(&h[i]).mul_add(acc - x, x).store(&mut v[i]);
            },
        );
    }

    /// One classical RK4 step; with `fresh`, `out` already holds `f(v - theta)`.
    #[inline(always)]
    fn rk4_step(&mut self, v: &mut [V::Row], fresh: bool) {
        let Work {
            theta,
            weights,
            h,
            h2,
            h6,
            ext,
            out,
            k: [k1, k2, k3],
            probe,
            ..
        } = self;
        let (weights, ext) = (*weights, &**ext);
        // Slope 1 at v; the next probe is v + h/2 k1.
        if !fresh {
            rates::<V>(theta, v, out);
        }
        drive::<V>(
            weights,
            ext,
            out,
            #[inline(always)]
            |i, acc| {
                let x = V::load(&v[i]);
                let d = acc - x;
                d.store(&mut k1[i]);
                V::load(&h2[i]).mul_add(d, x).store(&mut probe[i]);
            },
        );
        // Slopes 2 and 3 at the probe; the probes after them are v + h/2 k2 and v + h k3.
        for (k, h) in [(&mut **k2, *h2), (&mut **k3, *h)] {
            rates::<V>(theta, probe, out);
            drive::<V>(
                weights,
                ext,
                out,
                #[inline(always)]
                |i, acc| {
                    let d = acc - V::load(&probe[i]);
                    d.store(&mut k[i]);
                    V::load(&h[i])
                        .mul_add(d, V::load(&v[i]))
                        .store(&mut probe[i]);
                },
            );
        }
        // Slope 4 at the last probe, then v += h/6 (k1 + 2 k2 + 2 k3 + k4).
        rates::<V>(theta, probe, out);
        drive::<V>(
            weights,
            ext,
            out,
            #[inline(always)]
            |i, acc| {
                let k4 = acc - V::load(&probe[i]);
                let two = V::splat(2.0);
                let sum = V::load(&k1[i]) + two * V::load(&k2[i]) + two * V::load(&k3[i]) + k4;
                let x = V::load(&v[i]);
                V::load(&h6[i]).mul_add(sum, x).store(&mut v[i]);
            },
        );
    }
}

/// `ext = S I`, each sum over the sensors in order.
#[inline(always)]
fn sensor_drive<V: Vector>(sensor_weights: &[V::Row], inputs: &[V::Row], ext: &mut [V::Row]) {
    if inputs.is_empty() {
        for e in ext {
            V::splat(0.0).store(e);
        }
        return;
    }
    for (e, weights) in ext
        .iter_mut()
        .zip(sensor_weights.chunks_exact(inputs.len()))
    {
        let mut acc = V::splat(0.0);
        for (s, x) in weights.iter().zip(inputs) {
            acc = V::load(s).mul_add(V::load(x), acc);
        }
        acc.store(e);
    }
}

/// Firing rates `out = f(v - theta)`: [`RATE_GROUP`] neurons at a time where `V` allows it (see
/// [`Group`]), else one by one.
#[inline(always)]
pub(super) fn rates<V: Vector>(theta: &[V::Row], v: &[V::Row], out: &mut [V::Row]) {
    let mut at = 0;
    if V::INTERLEAVE {
        while at + RATE_GROUP <= out.len() {
            let mut x = Group([V::splat(0.0); RATE_GROUP]);
            for g in 0..RATE_GROUP {
                x.0[g] = V::load(&v[at + g]) - V::load(&theta[at + g]);
            }
            let y = sigmoid_lanes(x);
            for g in 0..RATE_GROUP {
                y.0[g].store(&mut out[at + g]);
            }
            at += RATE_GROUP;
        }
    }
    for i in at..out.len() {
        sigmoid_lanes(V::load(&v[i]) - V::load(&theta[i])).store(&mut out[i]);
    }
}

/// Neurons whose firing rates are computed together in [`rates`].
const RATE_GROUP: usize = 4;

/// Rows of the weights stored together, column by column (see [`weight_order`]).
const WEIGHT_GROUP: usize = 4;
const PREFETCH_COLUMNS: usize = 4;

/// The order in which `drive` reads the row-major `N x N` weights, as one stream: each group
/// of `WEIGHT_GROUP` (4) rows column by column (`w[i][0], w[i+1][0], ..., w[i][1], ...`), then the
/// rows left over, row by row. Row `i`'s weights start at `i * N` either way.
pub fn weight_order(n: usize) -> impl Iterator<Item = usize> {
    let full = n - n % WEIGHT_GROUP;
    let groups = (0..full)
        .step_by(WEIGHT_GROUP)
        .flat_map(move |i| (0..n).flat_map(move |j| (i..i + WEIGHT_GROUP).map(move |r| r * n + j)));
    groups.chain(full * n..n * n)
}

/// For every neuron `i`, `finish(i, ext_i + sum_j w_ij out_j)`, the sum taken in the order
/// `j = 0, 1, ...`. Rows go several at a time, as many as `V`'s registers hold
/// ([`Vector::SUM_REGISTERS`]): independent sums keep the multiply-add units busy, and the
/// result does not depend on the blocking.
#[inline(always)]
fn drive<V: Vector>(
    weights: &[V::Row],
    ext: &[V::Row],
    out: &[V::Row],
    finish: impl FnMut(usize, V),
) {
    match V::SUM_REGISTERS {
        0..=1 => drive_by::<V, 1>(weights, ext, out, finish),
        2..=3 => drive_by::<V, 2>(weights, ext, out, finish),
        _ => drive_by::<V, 4>(weights, ext, out, finish),
    }
}

/// [`drive`], `R` rows at a time within each group of [`WEIGHT_GROUP`] rows.
#[inline(always)]
fn drive_by<V: Vector, const R: usize>(
    weights: &[V::Row],
    ext: &[V::Row],
    out: &[V::Row],
    mut finish: impl FnMut(usize, V),
) {
    const { assert!(WEIGHT_GROUP.is_multiple_of(R)) };
    let n = out.len();
    let mut i = 0;
    while i + WEIGHT_GROUP <= n {
        let (columns, _) = weights[i * n..(i + WEIGHT_GROUP) * n].as_chunks::<WEIGHT_GROUP>();
        let mut first = 0;
        while first < WEIGHT_GROUP {
            let mut acc = [V::splat(0.0); R];
            for r in 0..R {
                acc[r] = V::load(&ext[i + first + r]);
            }
            for (j, (w, o)) in columns.iter().zip(out).enumerate() {
                if let Some(ahead) = columns.get(j + PREFETCH_COLUMNS) {
                    for r in 0..R {
                        V::prefetch(&ahead[first + r]);
                    }
                }
                let o = V::load(o);
                for r in 0..R {
                    acc[r] = V::load(&w[first + r]).mul_add(o, acc[r]);
                }
            }
            for r in 0..R {
                finish(i + first + r, acc[r]);
            }
            first += R;
        }
        i += WEIGHT_GROUP;
    }
    for i in i..n {
        let mut acc = V::load(&ext[i]);
        for (w, o) in weights[i * n..][..n].iter().zip(out) {
            acc = V::load(w).mul_add(V::load(o), acc);
        }
        finish(i, acc);
    }
}
