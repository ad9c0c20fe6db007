//! Classes of argument pairs for comparing [`super::hypot`] and
//! [`super::atan2`] with another libm's: random values at the scales the
//! simulation meets, random bits, ratios near each threshold, extremes
//! and specials.

/// A class of argument pairs.
#[derive(Clone, Copy, Debug)]
pub enum Class {
    /// Coordinates' differences in the box: up to 1.
    Box,
    /// Velocities: up to 10^-3.
    Velocity,
    /// Any bit pattern.
    Bits,
    /// The smaller about 2^-54 times the larger (where the sum takes
    /// over), and about 1 / sqrt(3) times (where the residual's form
    /// changes), and about equal.
    Ratios,
    /// The larger near 2^511 and the smaller near 2^-459 (where
    /// scaling starts), near overflow and underflow, subnormals.
    Extremes,
    /// Zeros of both signs, infinities, NaNs with payloads, beside
    /// ordinary values.
    Specials,
}

/// Every class.
pub const ALL: [Class; 6] = [
    Class::Box,
    Class::Velocity,
    Class::Bits,
    Class::Ratios,
    Class::Extremes,
    Class::Specials,
];

/// A small, fast generator (SplitMix64): the same pairs from the same
/// seed everywhere.
struct Mix(u64);

impl Mix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// `x` moved by up to `ulps` units in the last place either way.
    fn near(&mut self, x: f64, ulps: u64) -> f64 {
        let d = self.next() % (2 * ulps + 1);
        f64::from_bits((x.to_bits() + d).saturating_sub(ulps))
    }

    /// `1` or `-1`.
    fn sign(&mut self) -> f64 {
        if self.next() & 1 == 0 {
            1.0
        } else {
            -1.0
        }
    }
}

impl Class {
    /// The class's name.
    pub fn name(self) -> &'static str {
        match self {
            Class::Box => "box",
            Class::Velocity => "velocity",
            Class::Bits => "bits",
            Class::Ratios => "ratios",
            Class::Extremes => "extremes",
            Class::Specials => "specials",
        }
    }

    /// `count` pairs of the class from `seed`.
    pub fn pairs(self, count: u64, seed: u64) -> impl Iterator<Item = (f64, f64)> {
        let mut m = Mix(seed ^ (self as u64).wrapping_mul(0x1234_5678_9abc_def1));
        (0..count).map(move |_| self.pair(&mut m))
    }

    fn pair(self, m: &mut Mix) -> (f64, f64) {
        match self {
            Class::Box => (m.unit() * m.sign(), m.unit() * m.sign()),
            Class::Velocity => (m.unit() * 1e-3 * m.sign(), m.unit() * 1e-3 * m.sign()),
            Class::Bits => (f64::from_bits(m.next()), f64::from_bits(m.next())),
            Class::Ratios => {
                let scale = 2f64.powi((m.next() % 40) as i32 - 20);
                let big = (m.unit() + 0.5) * scale * m.sign();
                let ratio = match m.next() % 3 {
                    0 => m.near(2f64.powi(-54), 1 << 20),
                    1 => m.near(1.0 / 3f64.sqrt(), 1 << 40),
                    _ => m.near(1.0, 1 << 30),
                };
                (big, big * ratio * m.sign())
            }
            Class::Extremes => {
                let exp = |m: &mut Mix, around: i32| {
                    let e = around + (m.next() % 16) as i32 - 8;
                    (m.unit() + 1.0) * 2f64.powi(e)
                };
                let big = match m.next() % 4 {
                    0 => exp(m, 511),
                    1 => f64::from_bits(0x7fef_ffff_ffff_ffff - (m.next() % (1 << 40))),
                    2 => exp(m, -459),
                    _ => (m.unit() + 1.0) * 2f64.powi((m.next() % 2000) as i32 - 1000),
                };
                let small = match m.next() % 4 {
                    0 => exp(m, -459),
                    1 => f64::from_bits(m.next() % (1 << 52)), // subnormal
                    2 => big * m.unit(),
                    _ => big * m.near(2f64.powi(-54), 1 << 30),
                };
                let (a, b) = if m.next() & 1 == 0 {
                    (big, small)
                } else {
                    (small, big)
                };
                (a * m.sign(), b * m.sign())
            }
            Class::Specials => {
                let special = |m: &mut Mix| match m.next() % 6 {
                    0 => 0.0,
                    1 => f64::INFINITY,
                    // Quiet and signalling NaNs with payloads.
                    2 => f64::from_bits(0x7ff8_0000_0000_0000 | (m.next() >> 13)),
                    3 => f64::from_bits(0x7ff0_0000_0000_0001 | (m.next() >> 14)),
                    4 => f64::MIN_POSITIVE * m.unit(),
                    _ => m.unit(),
                };
                let a = special(m) * m.sign();
                (a, special(m) * m.sign())
            }
        }
    }
}
