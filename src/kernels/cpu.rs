//! What the CPU is and which instructions it has: the inputs of the kernel-choosing rule.

/// Who designed the CPU.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Vendor {
    /// `AuthenticAMD`.
    Amd,
    /// `GenuineIntel`.
    Intel,
    /// Anything else, and every non-x86 CPU.
    Other,
}

/// The facts about a CPU that [`super::choose`] looks at.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CpuFeatures {
    /// Its model as the CPU names itself (the CPUID brand string), for reports.
    pub model_name: String,
    /// Who designed it.
    pub vendor: Vendor,
    /// CPUID family with the extended family added (AMD Zen 2/3 0x17/0x19, Zen 4 0x19, Zen 5
    /// 0x1a; Intel Core 6); 0 off x86.
    pub family: u32,
    /// CPUID model with the extended model; 0 off x86.
    pub model: u32,
    /// AVX2.
    pub avx2: bool,
    /// AVX-512 Foundation.
    pub avx512f: bool,
    /// AVX-512 Byte and Word (the 64-byte compares of the run search).
    pub avx512bw: bool,
}

impl CpuFeatures {
    /// A CPU without any of the optional instructions (the portable set only).
    #[must_use]
    pub fn baseline(model_name: &str) -> Self {
        Self {
            model_name: model_name.to_owned(),
            vendor: Vendor::Other,
            family: 0,
            model: 0,
            avx2: false,
            avx512f: false,
            avx512bw: false,
        }
    }

    /// This machine's CPU.
    #[must_use]
    pub fn detect() -> Self {
        let cpu = Self::baseline(
            &model_name_from_os()
                .unwrap_or_else(|| format!("unknown {} CPU", std::env::consts::ARCH)),
        );
        #[cfg(target_arch = "x86_64")]
        let cpu = x86::filled(cpu);
        cpu
    }

    /// Whether this CPU has every instruction `set` needs.
    #[must_use]
    pub const fn can_run(&self, set: super::KernelSet) -> bool {
        use super::KernelSet;
        match set {
            KernelSet::Portable => true,
            KernelSet::Avx2 | KernelSet::Avx2Gather => self.avx2,
            KernelSet::Avx512 | KernelSet::Avx512Gather => {
                self.avx2 && self.avx512f && self.avx512bw
            }
        }
    }
}

/// `model name` of `/proc/cpuinfo` (Linux; x86 fills the brand string from CPUID instead).
fn model_name_from_os() -> Option<String> {
    let text = std::fs::read_to_string("/proc/cpuinfo").ok()?;
    text.lines()
        .filter_map(|l| l.split_once(':'))
        .find(|(k, _)| matches!(k.trim(), "model name" | "Model" | "Hardware"))
        .map(|(_, v)| v.trim().to_owned())
        .filter(|v| !v.is_empty())
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{CpuFeatures, Vendor};
    use std::arch::x86_64::{__cpuid, CpuidResult};

    /// Vendor, family, model, brand string and instruction sets from CPUID.
    pub(super) fn filled(mut cpu: CpuFeatures) -> CpuFeatures {
        let leaf0 = __cpuid(0);
        let vendor: Vec<u8> = [leaf0.ebx, leaf0.edx, leaf0.ecx]
            .iter()
            .flat_map(|r| r.to_le_bytes())
            .collect();
        cpu.vendor = match vendor.as_slice() {
            b"AuthenticAMD" => Vendor::Amd,
            b"GenuineIntel" => Vendor::Intel,
            _ => Vendor::Other,
        };
        if leaf0.eax >= 1 {
            let eax = __cpuid(1).eax;
            let (base_family, base_model) = ((eax >> 8) & 0xf, (eax >> 4) & 0xf);
            cpu.family = base_family
                + if base_family == 0xf {
                    (eax >> 20) & 0xff
                } else {
                    0
                };
            cpu.model = base_model
                | if base_family == 0xf || base_family == 6 {
                    ((eax >> 16) & 0xf) << 4
                } else {
                    0
                };
        }
        if __cpuid(0x8000_0000).eax >= 0x8000_0004 {
            let words: Vec<CpuidResult> = (0x8000_0002..=0x8000_0004).map(__cpuid).collect();
            let bytes: Vec<u8> = words
                .iter()
                .flat_map(|r| [r.eax, r.ebx, r.ecx, r.edx])
                .flat_map(u32::to_le_bytes)
                .take_while(|&b| b != 0)
                .collect();
            let brand = String::from_utf8_lossy(&bytes).trim().to_owned();
            if !brand.is_empty() {
                cpu.model_name = brand;
            }
        }
        cpu.avx2 = std::arch::is_x86_feature_detected!("avx2");
        cpu.avx512f = std::arch::is_x86_feature_detected!("avx512f");
        cpu.avx512bw = std::arch::is_x86_feature_detected!("avx512bw");
        cpu
    }
}
