//! 3-vectors of varying floats (structure of arrays: one register per component).

use core::ops::{Add, Mul, Neg, Sub};

use crate::Simd;

/// A varying 3-vector: lane `i` of `x`, `y`, `z` together form the vector of ray `i`.
#[derive(Clone, Copy, Debug)]
pub struct V3<S: Simd> {
    /// x components.
    pub x: S::F32,
    /// y components.
    pub y: S::F32,
    /// z components.
    pub z: S::F32,
}

impl<S: Simd> V3<S> {
    /// From three varying components.
    #[inline(always)]
    pub fn new(x: S::F32, y: S::F32, z: S::F32) -> Self {
        V3 { x, y, z }
    }

    /// A uniform vector broadcast to every lane.
    #[inline(always)]
    pub fn splat(s: S, v: [f32; 3]) -> Self {
        V3 {
            x: s.splat(v[0]),
            y: s.splat(v[1]),
            z: s.splat(v[2]),
        }
    }

    /// Dot product, `x*x' + y*y' + z*z'` (unfused, so identical on every backend).
    #[inline(always)]
    pub fn dot(self, o: Self) -> S::F32 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Cross product.
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        V3 {
            x: self.y * o.z - self.z * o.y,
            y: self.z * o.x - self.x * o.z,
            z: self.x * o.y - self.y * o.x,
        }
    }

    /// Every component times a varying scalar.
    #[inline(always)]
    pub fn scale(self, k: S::F32) -> Self {
        V3 {
            x: self.x * k,
            y: self.y * k,
            z: self.z * k,
        }
    }

    /// Euclidean length.
    #[inline(always)]
    pub fn length(self, s: S) -> S::F32 {
        s.sqrt(self.dot(self))
    }

    /// Unit vector in the same direction (division by the length; NaN for a zero vector).
    #[inline(always)]
    pub fn normalize(self, s: S) -> Self {
        self.scale(s.rsqrt(self.dot(self)))
    }

    /// `self + d * t` (a point along a ray).
    #[inline(always)]
    pub fn mul_add(self, d: Self, t: S::F32) -> Self {
        V3 {
            x: self.x + d.x * t,
            y: self.y + d.y * t,
            z: self.z + d.z * t,
        }
    }

    /// Per-lane `m ? a : b`.
    #[inline(always)]
    pub fn select(s: S, m: S::M, a: Self, b: Self) -> Self {
        V3 {
            x: s.select(m, a.x, b.x),
            y: s.select(m, a.y, b.y),
            z: s.select(m, a.z, b.z),
        }
    }
}

impl<S: Simd> Add for V3<S> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        V3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl<S: Simd> Sub for V3<S> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        V3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl<S: Simd> Mul for V3<S> {
    type Output = Self;
    /// Component-wise product.
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        V3 {
            x: self.x * o.x,
            y: self.y * o.y,
            z: self.z * o.z,
        }
    }
}

impl<S: Simd> Neg for V3<S> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        V3 {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}
