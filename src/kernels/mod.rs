//! Which kernels the hot loops (classification, the blobs' run search) use on this CPU.
//!
//! A [`KernelSet`] names one implementation of both loops; every set gives bit-identical
//! output (tested against [`KernelSet::Portable`]). Sets differ in speed, and which is fastest
//! depends on the CPU rather than on its instruction set alone. Table lookups by AVX2/AVX-512
//! *gathers* were assumed to win and do not everywhere: on AMD Zen 2 eotn with gathers ran at
//! 1.18× the C floor, and on this project's Zen 4 the gather kernels are slower than storing
//! the vector-computed cell indices and reading the cells with scalar loads (`docs/speed.md`).
//! So [`choose`] is a rule over [`CpuFeatures`] (vendor, family, model, instruction sets) that
//! picks gathers nowhere by default — the gather sets stay, forced by name and measured by
//! `eotn bench` on every CPU, so a CPU where they win shows it —, AVX-512 compares where they
//! run at full clock, the gather-free AVX2 set on other AVX2 CPUs, and the portable safe-Rust
//! loops elsewhere (aarch64 laptops among them; there the compiler vectorises them). The rule
//! is a pure function so a test holds it against a table of CPUs.
//!
//! `EOTN_KERNELS` (`portable`, `avx2`, `avx2-gather`, `avx512`, `avx512-gather` or `auto`)
//! overrides the rule; the CLI rejects an unknown name, or a set this CPU cannot run, with a
//! clear error ([`from_env`]) before doing anything else.

mod cpu;

use std::fmt;
use std::sync::OnceLock;

pub use cpu::{CpuFeatures, Vendor};

/// The environment variable that forces a kernel set.
pub const ENV_VAR: &str = "EOTN_KERNELS";

/// One implementation of the hot loops. All give the same output; they differ in speed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum KernelSet {
    /// Safe Rust on every CPU: scalar table lookups, run boundaries 8 pixels per 64-bit word.
    Portable,
    /// AVX2 without gathers: cell indices of 16 pixels computed in one vector, cells read with
    /// scalar loads; run boundaries 32 pixels per step.
    Avx2,
    /// AVX2 gathers, 8 cells per instruction; run boundaries 32 pixels per step.
    Avx2Gather,
    /// As [`KernelSet::Avx2`] for the cells, run boundaries 64 pixels per step (AVX-512 BW).
    Avx512,
    /// AVX-512 gathers, 16 cells per instruction; run boundaries 64 pixels per step.
    Avx512Gather,
}

impl KernelSet {
    /// Every set, portable first.
    pub const ALL: [Self; 5] = [
        Self::Portable,
        Self::Avx2,
        Self::Avx2Gather,
        Self::Avx512,
        Self::Avx512Gather,
    ];

    /// The name `EOTN_KERNELS` and `eotn bench` use.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Portable => "portable",
            Self::Avx2 => "avx2",
            Self::Avx2Gather => "avx2-gather",
            Self::Avx512 => "avx512",
            Self::Avx512Gather => "avx512-gather",
        }
    }

    /// The set of that name, if any.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }
}

impl fmt::Display for KernelSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Why `EOTN_KERNELS` was refused.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum KernelsError {
    /// Not the name of any set.
    Unknown(String),
    /// A set this CPU lacks the instructions for.
    Unsupported {
        /// The set asked for.
        set: KernelSet,
        /// The sets this CPU can run.
        runnable: Vec<KernelSet>,
    },
}

impl fmt::Display for KernelsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names =
            |sets: &[KernelSet]| sets.iter().map(|s| s.name()).collect::<Vec<_>>().join(", ");
        match self {
            Self::Unknown(name) => write!(
                f,
                "{ENV_VAR}={name:?} is not a kernel set; use auto or one of: {}",
                names(&KernelSet::ALL)
            ),
            Self::Unsupported { set, runnable } => write!(
                f,
                "{ENV_VAR}={set}: this CPU cannot run it (missing instructions); it can run: {}",
                names(runnable)
            ),
        }
    }
}

impl std::error::Error for KernelsError {}

/// The sets `cpu` has the instructions for, portable first.
#[must_use]
pub fn runnable(cpu: &CpuFeatures) -> Vec<KernelSet> {
    KernelSet::ALL
        .into_iter()
        .filter(|&s| cpu.can_run(s))
        .collect()
}

/// The set to use on `cpu` when nothing is forced.
///
/// No gathers (measured slower than scalar loads of vector-computed indices on Zen 2 and
/// Zen 4). AVX-512's 64-byte compares where the CPU has AVX-512 BW, except Intel's
/// Skylake-SP/Cascade Lake/Cooper Lake (family 6, model 0x55), which lower their clock for
/// 512-bit instructions; AVX2 on every other AVX2 CPU; the portable loops on the rest.
#[must_use]
pub fn choose(cpu: &CpuFeatures) -> KernelSet {
    let clocks_down_for_512 = cpu.vendor == Vendor::Intel && cpu.family == 6 && cpu.model == 0x55;
    if cpu.can_run(KernelSet::Avx512) && !clocks_down_for_512 {
        KernelSet::Avx512
    } else if cpu.can_run(KernelSet::Avx2) {
        KernelSet::Avx2
    } else {
        KernelSet::Portable
    }
}

/// The set for an `EOTN_KERNELS` value (`None`, empty or `auto`: [`choose`]).
///
/// # Errors
/// An unknown name, or a set `cpu` cannot run.
pub fn resolve(value: Option<&str>, cpu: &CpuFeatures) -> Result<KernelSet, KernelsError> {
    let name = value.map(str::trim).unwrap_or("");
    if name.is_empty() || name.eq_ignore_ascii_case("auto") {
        return Ok(choose(cpu));
    }
    let set = KernelSet::from_name(&name.to_ascii_lowercase())
        .ok_or_else(|| KernelsError::Unknown(name.to_owned()))?;
    if cpu.can_run(set) {
        Ok(set)
    } else {
        Err(KernelsError::Unsupported {
            set,
            runnable: runnable(cpu),
        })
    }
}

/// This machine's CPU, detected once.
#[must_use]
pub fn cpu() -> &'static CpuFeatures {
    static CPU: OnceLock<CpuFeatures> = OnceLock::new();
    CPU.get_or_init(CpuFeatures::detect)
}

/// The set `EOTN_KERNELS` asks for on this CPU (the rule's choice when it is unset).
///
/// # Errors
/// As [`resolve`]; the CLI reports it and stops.
pub fn from_env() -> Result<KernelSet, KernelsError> {
    let value = std::env::var(ENV_VAR).ok();
    resolve(value.as_deref(), cpu())
}

/// The set the hot loops use in this process: [`from_env`], decided once. A refused
/// `EOTN_KERNELS` (the CLI has already stopped on it; the app warns) falls back to the rule.
#[must_use]
pub fn active() -> KernelSet {
    static ACTIVE: OnceLock<KernelSet> = OnceLock::new();
    *ACTIVE.get_or_init(|| {
        from_env().unwrap_or_else(|e| {
            log::warn!("{e}; using the automatic choice");
            choose(cpu())
        })
    })
}

/// For the tests that hold every set against the portable one: the sets this CPU runs, the
/// others said as skips (`what` names the loop compared). An x86-64 CPU without AVX2 compares
/// nothing, a skip that fails under `CI=true`; sets a CPU lacks by design (AVX-512 on most
/// machines, every x86 set elsewhere) are noted in the summary without failing CI.
#[cfg(test)]
pub(crate) fn runnable_saying_the_rest(what: &str) -> Vec<KernelSet> {
    let sets = runnable(cpu());
    let lacking: Vec<&str> = KernelSet::ALL
        .into_iter()
        .filter(|s| !sets.contains(s))
        .map(KernelSet::name)
        .collect();
    if lacking.is_empty() {
        return sets;
    }
    let reason = format!(
        "this CPU cannot run the {} kernels, so their {what} was not compared with the portable one",
        lacking.join(", ")
    );
    let remedy = "run the tests on a CPU with those instructions (AVX2; AVX-512 F and BW)";
    if cfg!(target_arch = "x86_64") && !sets.contains(&KernelSet::Avx2) {
        crate::test_skip::skipped(&reason, remedy);
    } else {
        crate::test_skip::skip_noted(&reason, remedy);
    }
    sets
}

#[cfg(test)]
mod tests;
