//! A small deterministic random generator for the renderer and scenarios.
//!
//! SplitMix64 (Steele, Lea and Flood 2014): 64 bits of state, passes BigCrush, and is cheap
//! enough to draw a noise sample per pixel. Determinism matters more than quality here: the same
//! seed must give the same frames on every machine, so no platform generator is used.

/// A SplitMix64 generator.
#[derive(Debug, Clone)]
pub struct SimRng {
    state: u64,
}

impl SimRng {
    /// A generator from a seed.
    #[must_use]
    pub const fn new(seed: u64) -> Self {
        Self { state: seed }
    }

    /// A generator for one purpose derived from a seed and a stream number (e.g. the frame
    /// index), so frames can be rendered in any order and still match.
    #[must_use]
    pub fn derived(seed: u64, stream: u64) -> Self {
        let mut r = Self::new(seed ^ stream.wrapping_mul(0xD1B5_4A32_D192_ED03));
        r.next_u64();
        r
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        // 53 random mantissa bits.
        let v = (self.next_u64() >> 11) as f64;
        v * (1.0 / 9_007_199_254_740_992.0)
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// A standard normal sample (Box–Muller; one of the pair is discarded for simplicity).
    pub fn normal(&mut self) -> f64 {
        let u1 = self.unit().max(1e-300);
        let u2 = self.unit();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }

    /// An approximately normal sample from the sum of four uniforms: cheaper than
    /// [`Self::normal`], good enough for pixel noise (σ = 1, tails cut at ±3.46).
    pub fn fast_normal(&mut self) -> f32 {
        let bits = self.next_u64();
        let mut sum = 0.0_f32;
        for k in 0..4 {
            sum += f32::from(((bits >> (16 * k)) & 0xFFFF) as u16);
        }
        // Mean 2·65535, variance 4·65536²/12.
        (sum - 131_070.0) / 37_837.2
    }

    /// An index below `n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            return 0;
        }
        ((u128::from(self.next_u64()) * n as u128) >> 64) as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_sequence_and_streams_differ() {
        let a: Vec<u64> = (0..5).map(|_| SimRng::new(7).next_u64()).collect();
        assert!(a.windows(2).all(|w| w[0] == w[1]));
        let mut r = SimRng::derived(7, 1);
        let mut s = SimRng::derived(7, 2);
        assert_ne!(r.next_u64(), s.next_u64());
    }

    #[test]
    fn distributions_have_the_right_moments() {
        let mut r = SimRng::new(42);
        let n = 20_000;
        let (mut sum, mut sq) = (0.0, 0.0);
        for _ in 0..n {
            let v = r.normal();
            sum += v;
            sq += v * v;
        }
        let mean = sum / f64::from(n);
        let var = sq / f64::from(n) - mean * mean;
        assert!(
            mean.abs() < 0.03 && (var - 1.0).abs() < 0.05,
            "{mean} {var}"
        );
        let (mut sum, mut sq) = (0.0, 0.0);
        for _ in 0..n {
            let v = f64::from(r.fast_normal());
            sum += v;
            sq += v * v;
        }
        let mean = sum / f64::from(n);
        let var = sq / f64::from(n) - mean * mean;
        assert!(
            mean.abs() < 0.03 && (var - 1.0).abs() < 0.05,
            "{mean} {var}"
        );
        assert!((0..1000).all(|_| r.below(3) < 3));
        assert!((0..1000).all(|_| (0.0..1.0).contains(&r.unit())));
    }
}
