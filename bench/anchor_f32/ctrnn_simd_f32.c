/* The C anchor in single precision: ../shared/anchors/c/ctrnn_simd.c (SIMD across the
 * population in blocks of B networks, OpenMP over blocks, -ffast-math with libmvec's vector
 * exponential), copied and adapted to float for bench/integrate.py's f32 column (issue #49).
 *
 * What changed from the double original, and nothing else:
 *   - every array, accumulator and constant is float (`real`), and the exponential is expf, so
 *     that libmvec's 16-lane (AVX-512, _ZGVeN16v_expf) or 8-lane (AVX2, _ZGVdN8v_expf) float
 *     exponential is called;
 *   - the exponential's argument is clamped to [-87, 87], as dnnevo's f32 path clamps it: a
 *     float exponential overflows above 88.7, and fast-math's reciprocal of 1 + inf is NaN, not
 *     0 (without the clamp 344 of bench/integrate.py's 1000 networks at N = 30 ended in NaN);
 *     the lower bound keeps rates out of the slow subnormal range;
 *   - the default block is 32 networks, two 16-float registers, as the double anchor's 16 is
 *     two 8-double registers; the exported functions take float arrays and are named *_f32.
 * The rest (blocks gathered into [neuron][lane] order, four rows of W per pass, the inputs) is
 * the original's, whose header explains it.
 * Build: bench/anchor_f32/build.sh (gcc -O3 -march=native -mprefer-vector-width=512 -ffast-math
 *        -fopenmp -fPIC -shared ... -lmvec -lm).
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <omp.h>

#ifndef B
#define B 32
#endif
typedef float real;
#define IU 4 /* rows of W processed together */

static void run_block(int64_t p0, int64_t nb, int64_t N, int64_t T, const real *W,
                      const real *theta, const real *k, const real *S,
                      const real *v0, real *out, real *buf)
{
    real *Wb = buf;                 /* [N][N][B] */
    real *thb = Wb + N * N * B;     /* [N][B] */
    real *kb = thb + N * B;
    real *S0b = kb + N * B;
    real *S1b = S0b + N * B;
    real *vb = S1b + N * B;
    real *yb = vb + N * B;

    for (int64_t b = 0; b < B; b++) {
        const int live = b < nb; /* a padding lane past the population's end holds zeros */
        const int64_t p = p0 + (live ? b : 0);
        for (int64_t i = 0; i < N; i++) {
            for (int64_t j = 0; j < N; j++)
                Wb[(i * N + j) * B + b] = live ? W[p * N * N + i * N + j] : 0.0f;
            thb[i * B + b] = live ? theta[p * N + i] : 0.0f;
            kb[i * B + b] = live ? k[p * N + i] : 0.0f;
            S0b[i * B + b] = live ? S[(p * N + i) * 2] : 0.0f;
            S1b[i * B + b] = live ? S[(p * N + i) * 2 + 1] : 0.0f;
            vb[i * B + b] = live ? v0[p * N + i] : 0.0f;
        }
    }

    real I1[B] __attribute__((aligned(64)));
    real acc[IU][B] __attribute__((aligned(64)));
    for (int64_t t = 0; t < T; t++) {
        for (int64_t j = 0; j < N; j++) {
            real *restrict yj = yb + j * B;
            const real *restrict vj = vb + j * B, *restrict tj = thb + j * B;
#pragma omp simd aligned(yj, vj, tj : 64)
            for (int b = 0; b < B; b++)
                yj[b] = 1.0f / (1.0f + expf(fminf(fmaxf(tj[b] - vj[b], -87.0f), 87.0f)));
        }
        const real I0 = (t % 100) < 50 ? 1.0f : 0.0f;
#pragma omp simd
        for (int b = 0; b < B; b++) {
            const real e = I0 - yb[b];
            I1[b] = -(e * e);
        }
        int64_t i = 0;
        for (; i + IU <= N; i += IU) {
            for (int r = 0; r < IU; r++) {
#pragma omp simd
                for (int b = 0; b < B; b++)
                    acc[r][b] = S0b[(i + r) * B + b] * I0 + S1b[(i + r) * B + b] * I1[b];
            }
            for (int64_t j = 0; j < N; j++) {
                const real *restrict yj = yb + j * B;
                const real *restrict w0 = Wb + ((i + 0) * N + j) * B;
                const real *restrict w1 = Wb + ((i + 1) * N + j) * B;
                const real *restrict w2 = Wb + ((i + 2) * N + j) * B;
                const real *restrict w3 = Wb + ((i + 3) * N + j) * B;
#pragma omp simd
                for (int b = 0; b < B; b++) {
                    const real yv = yj[b];
                    acc[0][b] += w0[b] * yv;
                    acc[1][b] += w1[b] * yv;
                    acc[2][b] += w2[b] * yv;
                    acc[3][b] += w3[b] * yv;
                }
            }
            for (int r = 0; r < IU; r++) {
                real *restrict vi = vb + (i + r) * B;
                const real *restrict ki = kb + (i + r) * B;
#pragma omp simd
                for (int b = 0; b < B; b++)
                    vi[b] += ki[b] * (-vi[b] + acc[r][b]);
            }
        }
        for (; i < N; i++) {
#pragma omp simd
            for (int b = 0; b < B; b++)
                acc[0][b] = S0b[i * B + b] * I0 + S1b[i * B + b] * I1[b];
            for (int64_t j = 0; j < N; j++) {
                const real *restrict yj = yb + j * B;
                const real *restrict w0 = Wb + (i * N + j) * B;
#pragma omp simd
                for (int b = 0; b < B; b++)
                    acc[0][b] += w0[b] * yj[b];
            }
            real *restrict vi = vb + i * B;
            const real *restrict ki = kb + i * B;
#pragma omp simd
            for (int b = 0; b < B; b++)
                vi[b] += ki[b] * (-vi[b] + acc[0][b]);
        }
    }

    for (int64_t b = 0; b < nb; b++)
        for (int64_t i = 0; i < N; i++)
            out[(p0 + b) * N + i] = vb[i * B + b];
}

static real *alloc_buf(int64_t N)
{
    size_t n = (size_t)(N * N + 6 * N) * B;
    return aligned_alloc(64, ((n * sizeof(real) + 63) / 64) * 64);
}

/* single thread */
void run_popsimd_f32(int64_t P, int64_t N, int64_t T, const real *W, const real *theta,
                 const real *k, const real *S, const real *v0, real *out)
{
    real *buf = alloc_buf(N);
    for (int64_t p0 = 0; p0 < P; p0 += B) {
        int64_t nb = P - p0 < B ? P - p0 : B;
        run_block(p0, nb, N, T, W, theta, k, S, v0, out, buf);
    }
    free(buf);
}

/* OpenMP over blocks, nthreads threads */
void run_popsimd_omp_f32(int64_t P, int64_t N, int64_t T, const real *W, const real *theta,
                     const real *k, const real *S, const real *v0, real *out,
                     int64_t nthreads)
{
    int64_t nblocks = (P + B - 1) / B;
#pragma omp parallel num_threads(nthreads)
    {
        real *buf = alloc_buf(N);
#pragma omp for schedule(static)
        for (int64_t blk = 0; blk < nblocks; blk++) {
            int64_t p0 = blk * B;
            int64_t nb = P - p0 < B ? P - p0 : B;
            run_block(p0, nb, N, T, W, theta, k, S, v0, out, buf);
        }
        free(buf);
    }
}

int64_t block_size_f32(void) { return B; }
