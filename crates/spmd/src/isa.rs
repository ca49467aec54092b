//! Instruction-set selection: detection, the `BNS_ISA` override, and dispatch of a kernel to
//! the `#[target_feature]` entry point of the chosen backend.

use core::fmt;
use core::str::FromStr;

use crate::{Scalar, Simd};

/// One of the backends, ordered from narrowest to widest.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Isa {
    /// Plain Rust, one lane: the reference every other backend is tested against.
    Scalar,
    /// SSE4.1, 4 lanes.
    Sse41,
    /// AVX2 + FMA + F16C, 8 lanes.
    Avx2,
    /// AVX-512F, 16 lanes with mask registers.
    Avx512,
}

/// Why an instruction set could not be used.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum IsaError {
    /// The name is not one of `scalar`, `sse4.1`, `avx2`, `avx512`.
    #[error("unknown ISA {0:?}: expected one of scalar, sse4.1, avx2, avx512")]
    Unknown(String),
    /// The CPU (or OS) does not support the requested instruction set.
    #[error("this CPU does not support {requested} (supported here: {supported})")]
    Unsupported {
        /// What was asked for.
        requested: Isa,
        /// What this machine supports, comma separated.
        supported: String,
    },
    /// `BNS_ISA` holds something unusable.
    #[error("environment variable BNS_ISA: {0}")]
    Env(Box<IsaError>),
}

/// A computation written once, generic over the backend. [`Isa::dispatch`] runs it with the
/// backend's token inside that backend's `#[target_feature]` entry point.
///
/// Implementations must mark `run` `#[inline(always)]` (and everything hot that it calls), so
/// the body is compiled with the entry point's target features.
pub trait Kernel {
    /// What the kernel returns.
    type Output;
    /// Runs the kernel with backend `s`.
    fn run<S: Simd>(self, s: S) -> Self::Output;
}

impl Isa {
    /// Every backend, narrowest first.
    pub const ALL: [Isa; 4] = [Isa::Scalar, Isa::Sse41, Isa::Avx2, Isa::Avx512];

    /// The name used by `BNS_ISA`, `--isa` and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Scalar => "scalar",
            Isa::Sse41 => "sse4.1",
            Isa::Avx2 => "avx2",
            Isa::Avx512 => "avx512",
        }
    }

    /// Lanes per varying value.
    pub fn lanes(self) -> usize {
        match self {
            Isa::Scalar => 1,
            Isa::Sse41 => 4,
            Isa::Avx2 => 8,
            Isa::Avx512 => 16,
        }
    }

    /// Whether this CPU and OS can run the backend (checked with CPUID, cached by std).
    ///
    /// `BNS_CPU_LIMIT=<isa>` makes every wider backend count as unsupported, to exercise the
    /// "CPU lacks it" paths on a machine that has everything (tests and demos only).
    pub fn is_supported(self) -> bool {
        if cpu_limit().is_some_and(|limit| self > limit) {
            return false;
        }
        match self {
            Isa::Scalar => true,
            #[cfg(target_arch = "x86_64")]
            Isa::Sse41 => crate::x86::sse41::Sse41::try_new().is_some(),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => crate::x86::avx2::Avx2::try_new().is_some(),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => crate::x86::avx512::Avx512::try_new().is_some(),
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// A table of the backends (`bnsview isa`): one line each with its lanes, whether this
    /// CPU supports it, and a `*` on `selected`.
    pub fn table(selected: Isa) -> String {
        let mut t = format!(
            "{:<8} {:>5}  {:<9}  selected\n",
            "isa", "lanes", "supported"
        );
        for isa in Isa::ALL {
            let supported = if isa.is_supported() { "yes" } else { "no" };
            let star = if isa == selected { "*" } else { "" };
            t += &format!(
                "{:<8} {:>5}  {supported:<9}  {star}\n",
                isa.name(),
                isa.lanes()
            );
        }
        t
    }

    /// The backends this machine supports, narrowest first.
    pub fn supported() -> Vec<Isa> {
        Isa::ALL.into_iter().filter(|i| i.is_supported()).collect()
    }

    /// The backends a test or benchmark should cover: the one named by `BNS_ISA` if set (so
    /// `cargo xtask matrix` can force each in turn), else every supported backend.
    ///
    /// Panics with a clear message if `BNS_ISA` is unknown or unsupported: a test run asked
    /// for something it cannot do must not pass silently.
    pub fn under_test() -> Vec<Isa> {
        match std::env::var("BNS_ISA") {
            Ok(v) if !v.trim().is_empty() => {
                vec![Isa::select(None).unwrap_or_else(|e| panic!("{e}"))]
            }
            _ => Isa::supported(),
        }
    }

    /// The widest supported backend.
    pub fn detect() -> Isa {
        Isa::ALL
            .into_iter()
            .rev()
            .find(|i| i.is_supported())
            .unwrap_or(Isa::Scalar)
    }

    /// Checks that this backend is supported, with an error naming what is.
    pub fn check(self) -> Result<Isa, IsaError> {
        if self.is_supported() {
            Ok(self)
        } else {
            Err(IsaError::Unsupported {
                requested: self,
                supported: Isa::supported()
                    .iter()
                    .map(|i| i.name())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
        }
    }

    /// The backend to use: `requested` (e.g. from `--isa`) if given, else `BNS_ISA` if set and
    /// non-empty, else [`Isa::detect`]. Errors if the choice is unknown or unsupported.
    pub fn select(requested: Option<Isa>) -> Result<Isa, IsaError> {
        if let Some(isa) = requested {
            return isa.check();
        }
        match std::env::var("BNS_ISA") {
            Ok(v) if !v.trim().is_empty() => v
                .parse::<Isa>()
                .and_then(Isa::check)
                .map_err(|e| IsaError::Env(Box::new(e))),
            _ => Ok(Isa::detect()),
        }
    }

    /// Runs `kernel` on this backend, inside its `#[target_feature]` entry point.
    ///
    /// Panics if the CPU does not support the backend (use [`Isa::select`] or
    /// [`Isa::check`] first to report that as an error).
    #[inline]
    pub fn dispatch<K: Kernel>(self, kernel: K) -> K::Output {
        match self {
            Isa::Scalar => kernel.run(Scalar),
            #[cfg(target_arch = "x86_64")]
            Isa::Sse41 => crate::x86::sse41::dispatch(kernel),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => crate::x86::avx2::dispatch(kernel),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => crate::x86::avx512::dispatch(kernel),
            #[cfg(not(target_arch = "x86_64"))]
            _ => panic!("{} is not available on this architecture", self.name()),
        }
    }
}

/// The `BNS_CPU_LIMIT` cap, read once.
fn cpu_limit() -> Option<Isa> {
    static LIMIT: std::sync::OnceLock<Option<Isa>> = std::sync::OnceLock::new();
    *LIMIT.get_or_init(|| {
        std::env::var("BNS_CPU_LIMIT")
            .ok()
            .and_then(|v| v.parse().ok())
    })
}

impl fmt::Display for Isa {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Isa {
    type Err = IsaError;
    fn from_str(s: &str) -> Result<Isa, IsaError> {
        match s.trim().to_ascii_lowercase().as_str() {
            "scalar" => Ok(Isa::Scalar),
            "sse4.1" | "sse41" | "sse4_1" | "sse" => Ok(Isa::Sse41),
            "avx2" => Ok(Isa::Avx2),
            "avx512" | "avx-512" | "avx512f" => Ok(Isa::Avx512),
            _ => Err(IsaError::Unknown(s.to_string())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for isa in Isa::ALL {
            assert_eq!(isa.name().parse::<Isa>().unwrap(), isa);
        }
        assert!(matches!(
            "avx1024".parse::<Isa>(),
            Err(IsaError::Unknown(_))
        ));
    }

    #[test]
    fn detect_is_supported_and_widest() {
        let best = Isa::detect();
        assert!(best.is_supported());
        assert!(Isa::ALL
            .iter()
            .filter(|i| **i > best)
            .all(|i| !i.is_supported()));
        assert!(Isa::Scalar.is_supported());
    }

    #[test]
    fn explicit_request_wins_and_is_checked() {
        assert_eq!(Isa::select(Some(Isa::Scalar)).unwrap(), Isa::Scalar);
        for isa in Isa::ALL {
            assert_eq!(Isa::select(Some(isa)).is_ok(), isa.is_supported());
        }
    }

    struct LaneCount;
    impl Kernel for LaneCount {
        type Output = (usize, Isa);
        #[inline(always)]
        fn run<S: Simd>(self, _s: S) -> (usize, Isa) {
            (S::LANES, S::ISA)
        }
    }

    #[test]
    fn dispatch_reaches_the_requested_backend() {
        for isa in Isa::supported() {
            assert_eq!(isa.dispatch(LaneCount), (isa.lanes(), isa));
        }
    }
}
