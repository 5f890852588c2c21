//! Just enough double-double arithmetic (an unevaluated sum `hi + lo` of two
//! f64, about 32 significant digits) to run the Legendre recurrence for the
//! small-n rules beyond f64 rounding. Error-free transformations: Knuth's
//! TwoSum and Dekker's split product (no FMA needed).

/// `hi + lo` with `|lo| <= ulp(hi)/2`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DD {
    pub hi: f64,
    pub lo: f64,
}

/// `a + b = s + e` exactly.
#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `a + b = s + e` exactly, given `|a| >= |b|`.
#[inline]
fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

/// Dekker's split of `a` into two 26-bit halves.
#[inline]
fn split(a: f64) -> (f64, f64) {
    let t = 134_217_729.0 * a; // 2^27 + 1
    let hi = t - (t - a);
    (hi, a - hi)
}

/// `a b = p + e` exactly.
#[inline]
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

impl DD {
    /// The f64 `x` exactly.
    pub const fn from(x: f64) -> DD {
        DD { hi: x, lo: 0.0 }
    }

    /// The nearest f64.
    pub fn round(self) -> f64 {
        self.hi + self.lo
    }

    /// `self + other`.
    #[inline]
    pub fn add(self, other: DD) -> DD {
        let (s, e) = two_sum(self.hi, other.hi);
        let (hi, lo) = quick_two_sum(s, e + self.lo + other.lo);
        DD { hi, lo }
    }

    /// `self - other`.
    #[inline]
    pub fn sub(self, other: DD) -> DD {
        self.add(DD {
            hi: -other.hi,
            lo: -other.lo,
        })
    }

    /// `self * b` for an f64 `b`.
    #[inline]
    pub fn mul_f(self, b: f64) -> DD {
        let (p, e) = two_prod(self.hi, b);
        let (hi, lo) = quick_two_sum(p, e + self.lo * b);
        DD { hi, lo }
    }

    /// `self * other`.
    #[inline]
    pub fn mul(self, other: DD) -> DD {
        let (p, e) = two_prod(self.hi, other.hi);
        let (hi, lo) = quick_two_sum(p, e + self.hi * other.lo + self.lo * other.hi);
        DD { hi, lo }
    }

    /// `self / b` for an f64 `b`: one f64 quotient and one correction.
    #[inline]
    pub fn div_f(self, b: f64) -> DD {
        let q1 = self.hi / b;
        let r = self.sub(DD::from(b).mul_f(q1));
        let q2 = r.hi / b;
        let (hi, lo) = quick_two_sum(q1, q2);
        DD { hi, lo }
    }

    /// `self / other`.
    #[inline]
    pub fn div(self, other: DD) -> DD {
        let q1 = self.hi / other.hi;
        let r = self.sub(other.mul_f(q1));
        let q2 = r.hi / other.hi;
        let (hi, lo) = quick_two_sum(q1, q2);
        DD { hi, lo }
    }
}
