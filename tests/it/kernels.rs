//! Every kernel set this CPU can run gives the portable set's output bit for bit: the classified
//! image, the runs and every blob, on random frames and tables (all three table resolutions,
//! widths off the kernels' 16/32/64-pixel blocks) and on real frames (the B-Human Nao log
//! shipped in `streams/` with its table, the shipped sample and overhead streams, and the
//! NUbots tables of `../shared/data` over the Nao frames).

use eotn::blobs::{BlobSet, Connectivity};
use eotn::classify::{ClassifiedImage, classify_into_with};
use eotn::frame::Frame;
use eotn::kernels::{KernelSet, cpu, runnable};
use eotn::lut::{ColourClass, LookupTable};
use eotn::streams::StreamReader;

use crate::common::{repo_file, shared_file, skip_noted, skipped};

/// The sets to hold against the portable one (every runnable one but itself). The sets this CPU
/// cannot run are a visible skip: an x86-64 CPU without AVX2 compares nothing, which fails under
/// `CI=true`; a set lacking by design (AVX-512 on most CPUs, every x86 set elsewhere) is listed
/// in the summary without failing CI.
fn other_sets() -> Vec<KernelSet> {
    // Said once per test (each test runs on its own thread), not once per frame compared.
    thread_local! {
        static SAID: std::cell::OnceCell<Vec<KernelSet>> = const { std::cell::OnceCell::new() };
    }
    SAID.with(|said| said.get_or_init(other_sets_said).clone())
}

fn other_sets_said() -> Vec<KernelSet> {
    let runnable = runnable(cpu());
    let lacking: Vec<&str> = KernelSet::ALL
        .into_iter()
        .filter(|s| !runnable.contains(s))
        .map(KernelSet::name)
        .collect();
    if !lacking.is_empty() {
        let reason = format!(
            "this CPU cannot run the {} kernels, so they were not compared with the portable ones",
            lacking.join(", ")
        );
        let remedy = "run the tests on a CPU with those instructions (AVX2; AVX-512 F and BW)";
        if cfg!(target_arch = "x86_64") && !runnable.contains(&KernelSet::Avx2) {
            skipped(&reason, remedy);
        } else {
            skip_noted(&reason, remedy);
        }
    }
    runnable
        .into_iter()
        .filter(|&s| s != KernelSet::Portable)
        .collect()
}

/// Classifies and finds blobs (both connectivities) with `set`.
fn run(set: KernelSet, frame: &Frame, lut: &LookupTable) -> (ClassifiedImage, [BlobSet; 2]) {
    let mut img = ClassifiedImage::default();
    classify_into_with(set, frame, lut, &mut img);
    let blobs = [Connectivity::Eight, Connectivity::Four].map(|c| {
        let mut b = BlobSet::default();
        b.set_kernels(set);
        b.find(&img, c);
        b
    });
    (img, blobs)
}

/// Asserts every set agrees with the portable one on `frame`; returns the blobs found (8-conn).
fn assert_all_sets_agree(frame: &Frame, lut: &LookupTable, what: &str) -> usize {
    let (img, blobs) = run(KernelSet::Portable, frame, lut);
    for set in other_sets() {
        let (other_img, other_blobs) = run(set, frame, lut);
        assert!(
            other_img == img,
            "{set}: classified image differs on {what}"
        );
        for (a, b) in other_blobs.iter().zip(&blobs) {
            assert_eq!(a.runs(), b.runs(), "{set}: runs differ on {what}");
            assert_eq!(a.all(), b.all(), "{set}: blobs differ on {what}");
        }
    }
    blobs[0].all().len()
}

/// xorshift64: reproducible random bytes.
fn rng(mut state: u64) -> impl FnMut() -> u64 {
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    }
}

#[test]
fn every_kernel_set_equals_the_portable_one_on_random_frames() {
    let mut next = rng(0x9e37_79b9_7f4a_7c15);
    for bits in [6u8, 7, 8] {
        let mut t = LookupTable::new(bits).unwrap();
        // Blocky classes (as real tables) with speckle, so runs of every length occur.
        for i in 0..t.cells().len() {
            let code = if next().is_multiple_of(8) {
                next() % 11
            } else {
                (i as u64 >> 9) % 11
            };
            t.set(i, ColourClass::from_code(code as u8).unwrap());
        }
        for (w, h) in [(640, 480), (208, 160), (34, 3), (2, 5), (1922, 2), (130, 9)] {
            let mut data: Vec<u8> = (0..w * h * 2).map(|_| next() as u8).collect();
            // Smooth stretches as well as noise: copy pixel pairs forward at random.
            for i in 4..data.len() {
                if !next().is_multiple_of(4) {
                    data[i] = data[i - 4];
                }
            }
            if let Some(last) = data.last_chunk_mut::<4>() {
                *last = [255; 4]; // the table's last cells
            }
            let frame = Frame::from_uyvy(w, h, data).unwrap();
            assert_all_sets_agree(&frame, &t, &format!("random {w}x{h}, {bits} bits"));
        }
    }
}

/// Every frame of a shipped stream with a table, through every set; the blobs found in all.
fn check_stream(stream: &str, lut: &LookupTable, what: &str) -> usize {
    let mut reader = StreamReader::open(&repo_file(stream)).unwrap();
    assert!(!reader.is_empty(), "{stream}");
    (0..reader.len())
        .map(|i| {
            let rec = reader.read(i).unwrap();
            assert_all_sets_agree(&rec.frame, lut, &format!("{what} frame {i}"))
        })
        .sum()
}

#[test]
fn every_kernel_set_equals_the_portable_one_on_real_frames() {
    let bhuman = LookupTable::load(&repo_file("lookup_tables/bhuman2009.lut")).unwrap();
    let blobs = check_stream(
        "streams/bhuman2009.mcap",
        &bhuman,
        "B-Human log (6-bit table)",
    );
    assert!(blobs > 1000, "the Nao frames make blobs: {blobs}");
    let sample = LookupTable::load(&repo_file("lookup_tables/sample.lut")).unwrap();
    assert!(check_stream("streams/sample.mcap", &sample, "sample (7-bit)") > 0);
    let sim = LookupTable::load(&repo_file("lookup_tables/sim.lut")).unwrap();
    assert!(check_stream("streams/sim-overhead-game.mcap", &sim, "overhead game") > 0);
    // Other teams' 7-bit tables over the real Nao frames (skipped without ../shared).
    for name in ["nubots2013-default1.lut", "nubots2013-lab-NUbot2.lut"] {
        let Some(path) = shared_file(&format!("data/luts/{name}")) else {
            continue;
        };
        let converted = eotn::lut::convert::convert_file(&path, None, None).unwrap();
        check_stream("streams/bhuman2009.mcap", &converted.table, name);
    }
}
