//! The choosing rule against a table of CPUs, and `EOTN_KERNELS`'s parsing.

use super::*;

/// A CPU as CPUID describes it.
fn cpu(vendor: Vendor, family: u32, model: u32, isa: &str) -> CpuFeatures {
    CpuFeatures {
        model_name: format!("{vendor:?} {family:#x}/{model:#x}"),
        vendor,
        family,
        model,
        avx2: isa.contains("avx2"),
        avx512f: isa.contains("avx512"),
        avx512bw: isa.contains("avx512"),
    }
}

#[test]
fn the_rule_picks_no_gathers_and_avx512_only_at_full_clock() {
    use KernelSet::{Avx2, Avx512, Portable};
    use Vendor::{Amd, Intel, Other};
    let table = [
        // (what, vendor, family, model, instructions, expected)
        ("Zen 1 (Ryzen 1800X)", Amd, 0x17, 0x01, "avx2", Avx2),
        (
            "Zen 2 (EPYC 7742): slow gathers",
            Amd,
            0x17,
            0x31,
            "avx2",
            Avx2,
        ),
        ("Zen 3 (Ryzen 5950X)", Amd, 0x19, 0x21, "avx2", Avx2),
        (
            "Zen 4 (EPYC 9004, this machine)",
            Amd,
            0x19,
            0x11,
            "avx2 avx512",
            Avx512,
        ),
        (
            "Zen 4 (Ryzen 7950X)",
            Amd,
            0x19,
            0x61,
            "avx2 avx512",
            Avx512,
        ),
        (
            "Zen 5 (Ryzen 9950X)",
            Amd,
            0x1a,
            0x44,
            "avx2 avx512",
            Avx512,
        ),
        ("Zen 5, AVX-512 off", Amd, 0x1a, 0x44, "avx2", Avx2),
        ("Haswell (i7-4770)", Intel, 6, 0x3c, "avx2", Avx2),
        (
            "Skylake-SP: 512-bit clocks down",
            Intel,
            6,
            0x55,
            "avx2 avx512",
            Avx2,
        ),
        ("Ice Lake server", Intel, 6, 0x6a, "avx2 avx512", Avx512),
        ("Sapphire Rapids", Intel, 6, 0x8f, "avx2 avx512", Avx512),
        ("Alder Lake", Intel, 6, 0x97, "avx2", Avx2),
        ("Sandy Bridge: no AVX2", Intel, 6, 0x2a, "", Portable),
        ("Jaguar: no AVX2", Amd, 0x16, 0x00, "", Portable),
        ("aarch64 laptop", Other, 0, 0, "", Portable),
    ];
    for (what, vendor, family, model, isa, expected) in table {
        let c = cpu(vendor, family, model, isa);
        assert_eq!(choose(&c), expected, "{what}");
        assert!(c.can_run(choose(&c)), "{what}: chose a set it cannot run");
    }
}

#[test]
fn runnable_sets_follow_the_instructions() {
    let zen2 = cpu(Vendor::Amd, 0x17, 0x31, "avx2");
    assert_eq!(
        runnable(&zen2),
        [KernelSet::Portable, KernelSet::Avx2, KernelSet::Avx2Gather]
    );
    assert_eq!(
        runnable(&CpuFeatures::baseline("arm")),
        [KernelSet::Portable]
    );
    assert_eq!(
        runnable(&cpu(Vendor::Amd, 0x19, 0x11, "avx2 avx512")),
        KernelSet::ALL
    );
}

#[test]
fn forced_names_are_checked_against_the_cpu() {
    let zen2 = cpu(Vendor::Amd, 0x17, 0x31, "avx2");
    for auto in [None, Some(""), Some("auto"), Some(" AUTO ")] {
        assert_eq!(resolve(auto, &zen2), Ok(KernelSet::Avx2), "{auto:?}");
    }
    assert_eq!(
        resolve(Some("avx2-gather"), &zen2),
        Ok(KernelSet::Avx2Gather)
    );
    assert_eq!(resolve(Some("Portable"), &zen2), Ok(KernelSet::Portable));
    let unknown = resolve(Some("sse9"), &zen2).unwrap_err();
    assert_eq!(unknown, KernelsError::Unknown("sse9".into()));
    let text = unknown.to_string();
    assert!(
        text.contains("EOTN_KERNELS=\"sse9\"") && text.contains("avx512"),
        "{text}"
    );
    let unsupported = resolve(Some("avx512"), &zen2).unwrap_err();
    let text = unsupported.to_string();
    assert!(
        matches!(
            unsupported,
            KernelsError::Unsupported {
                set: KernelSet::Avx512,
                ..
            }
        ) && text.contains("cannot run")
            && text.contains("portable, avx2, avx2-gather"),
        "{text}"
    );
    assert!(resolve(Some("avx2"), &CpuFeatures::baseline("arm")).is_err());
}

#[test]
fn names_round_trip() {
    for set in KernelSet::ALL {
        assert_eq!(KernelSet::from_name(set.name()), Some(set));
        assert_eq!(set.to_string(), set.name());
    }
}

#[test]
fn this_cpu_is_detected_consistently_with_the_standard_library() {
    let c = CpuFeatures::detect();
    assert!(!c.model_name.is_empty());
    #[cfg(target_arch = "x86_64")]
    {
        assert_eq!(c.avx2, std::arch::is_x86_feature_detected!("avx2"));
        assert_eq!(c.avx512bw, std::arch::is_x86_feature_detected!("avx512bw"));
        if c.vendor != Vendor::Other {
            assert!(c.family > 0, "{c:?}");
        }
    }
    assert!(c.can_run(choose(&c)));
}
