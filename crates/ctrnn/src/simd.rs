//! Which vector kernel steps the networks, chosen when the program runs.
//!
//! One build runs on every CPU of its architecture. The first step picks the fastest kernel the
//! CPU has, unless the environment variable [`ENV`] (`DNNEVO_SIMD`) names another; a program can
//! also switch at any time with [`set_kernel`]. Every kernel computes the same IEEE operations in
//! the same order, so the choice changes speed, never a result.
//!
//! | kernel | CPUs | lanes per register |
//! |---|---|---|
//! | `avx512` | x86-64 with AVX-512F | 8 |
//! | `avx2` | x86-64 with AVX2 and FMA | 4 |
//! | `neon` | every 64-bit ARM (AArch64) CPU | 2 |
//! | `portable` | any | 1 (what the compiler makes of plain `f64` code) |
//!
//! # Example
//! ```
//! use ctrnn::simd::{self, Kernel};
//! assert!(Kernel::Portable.is_supported());
//! simd::set_kernel(Kernel::Portable)?;
//! assert_eq!(simd::kernel(), Kernel::Portable);
//! simd::set_kernel(simd::best())?;
//! # Ok::<(), ctrnn::Error>(())
//! ```

use std::fmt;
use std::str::FromStr;
use std::sync::atomic::{AtomicU8, Ordering};

use crate::error::{Error, Result};

/// The environment variable that forces a kernel: `avx512`, `avx2`, `neon` or `portable`.
pub const ENV: &str = "DNNEVO_SIMD";

/// A vector kernel of the integrator.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kernel {
    /// Plain `f64` code for any CPU; exact everywhere, and slow where the CPU has no fused
    /// multiply-add (then done in software).
    Portable,
    /// 256-bit registers, four networks each, with fused multiply-add (x86-64 AVX2 + FMA).
    Avx2,
    /// 512-bit registers, eight networks each (x86-64 AVX-512F).
    Avx512,
    /// 128-bit registers, two networks each, with fused multiply-add (AArch64; every 64-bit ARM
    /// CPU has it).
    Neon,
}

impl Kernel {
    /// Every kernel, slowest first within an architecture.
    pub const ALL: [Kernel; 4] = [Kernel::Portable, Kernel::Avx2, Kernel::Avx512, Kernel::Neon];

    /// The name used by [`ENV`] and [`FromStr`].
    pub fn name(self) -> &'static str {
        match self {
            Kernel::Portable => "portable",
            Kernel::Avx2 => "avx2",
            Kernel::Avx512 => "avx512",
            Kernel::Neon => "neon",
        }
    }

    /// Whether this CPU can run the kernel.
    pub fn is_supported(self) -> bool {
        match self {
            Kernel::Portable => true,
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx2 => {
                std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512 => {
                std::arch::is_x86_feature_detected!("avx512f") && Kernel::Avx2.is_supported()
            }
            #[cfg(not(target_arch = "x86_64"))]
            Kernel::Avx2 | Kernel::Avx512 => false,
            Kernel::Neon => cfg!(target_arch = "aarch64"),
        }
    }

    fn code(self) -> u8 {
        self as u8 + 1
    }

    fn from_code(code: u8) -> Option<Kernel> {
        Kernel::ALL.into_iter().find(|k| k.code() == code)
    }
}

impl fmt::Display for Kernel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Kernel {
    type Err = Error;
    fn from_str(s: &str) -> Result<Kernel> {
        parse(s).map_err(Error::InvalidArgument)
    }
}

fn parse(s: &str) -> std::result::Result<Kernel, String> {
    Kernel::ALL
        .into_iter()
        .find(|k| k.name() == s)
        .ok_or_else(|| {
            format!(
                "unknown SIMD kernel {s:?}; choose one of {}",
                names(&Kernel::ALL)
            )
        })
}

fn names(kernels: &[Kernel]) -> String {
    kernels
        .iter()
        .map(|k| k.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The kernels this CPU can run, slowest first.
pub fn supported() -> Vec<Kernel> {
    Kernel::ALL
        .into_iter()
        .filter(|k| k.is_supported())
        .collect()
}

/// The fastest kernel this CPU can run.
pub fn best() -> Kernel {
    *supported().last().unwrap_or(&Kernel::Portable)
}

/// The kernel that [`ENV`] asks for, if it is set. An unknown name, or a kernel this CPU cannot
/// run, is an error that names the variable.
pub fn from_env() -> Result<Option<Kernel>> {
    let Ok(value) = std::env::var(ENV) else {
        return Ok(None);
    };
    parse(value.trim())
        .and_then(|k| unsupported(k).map_or(Ok(Some(k)), Err))
        .map_err(|e| Error::InvalidArgument(format!("{ENV}={value:?}: {e}")))
}

/// Why this CPU cannot run `kernel`, if it cannot.
fn unsupported(kernel: Kernel) -> Option<String> {
    (!kernel.is_supported()).then(|| {
        format!(
            "this CPU cannot run the {kernel} kernel; it can run {}",
            names(&supported())
        )
    })
}

/// The kernel in use; 0 until the first step chooses one.
static CURRENT: AtomicU8 = AtomicU8::new(0);

/// The kernel that steps networks from now on. The first call chooses it: the one [`ENV`] names
/// if that is valid, else [`best`]. (A program that must not ignore a bad [`ENV`] calls
/// [`from_env`] itself first; the Python package does, when it is imported.)
#[inline]
pub fn kernel() -> Kernel {
    match Kernel::from_code(CURRENT.load(Ordering::Relaxed)) {
        Some(k) => k,
        None => choose(),
    }
}

#[cold]
fn choose() -> Kernel {
    let chosen = from_env().ok().flatten().unwrap_or_else(best);
    CURRENT.store(chosen.code(), Ordering::Relaxed);
    chosen
}

/// Makes every later step use `kernel`. Results do not change, so this may be called at any time,
/// from any thread. Fails if this CPU cannot run it.
pub fn set_kernel(kernel: Kernel) -> Result<()> {
    if let Some(why) = unsupported(kernel) {
        return Err(Error::InvalidArgument(why));
    }
    CURRENT.store(kernel.code(), Ordering::Relaxed);
    Ok(())
}

/// The CPU features the kernels look for, and whether this CPU has each.
pub fn cpu_features() -> Vec<(&'static str, bool)> {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::is_x86_feature_detected as has;
        vec![
            ("sse2", has!("sse2")),
            ("avx", has!("avx")),
            ("fma", has!("fma")),
            ("avx2", has!("avx2")),
            ("avx512f", has!("avx512f")),
        ]
    }
    #[cfg(target_arch = "aarch64")]
    {
        vec![("neon", std::arch::is_aarch64_feature_detected!("neon"))]
    }
    #[cfg(not(any(target_arch = "x86_64", target_arch = "aarch64")))]
    {
        Vec::new()
    }
}
