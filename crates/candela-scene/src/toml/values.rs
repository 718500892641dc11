//! Value types of the TOML scene format that check themselves while they are read, so
//! that an error points at the offending value: finite numbers, 2- and 3-vectors, and
//! colours given either as `[r, g, b]` or as one grey number.

use std::fmt;

use glam::{Vec2, Vec3};
use serde::de::{self, Deserialize, Deserializer, SeqAccess, Visitor};

/// A finite number (TOML integers are accepted too). `nan`, `inf` and values beyond the
/// range of `f32` are errors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Num(pub f32);

fn finite<E: de::Error>(v: f64) -> Result<Num, E> {
    let f = v as f32;
    if f.is_finite() {
        Ok(Num(f))
    } else if v.is_finite() {
        Err(E::custom(format!("number {v} is out of range")))
    } else {
        Err(E::custom(format!(
            "expected a finite number, found {}",
            if v.is_nan() { "nan" } else { "inf" }
        )))
    }
}

struct NumVisitor;

impl<'de> Visitor<'de> for NumVisitor {
    type Value = Num;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number")
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Num, E> {
        finite(v as f64)
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Num, E> {
        finite(v as f64)
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Num, E> {
        finite(v)
    }
}

impl<'de> Deserialize<'de> for Num {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(NumVisitor)
    }
}

/// Reads exactly `N` numbers from an array.
fn read_array<'de, A: SeqAccess<'de>, const N: usize>(mut seq: A) -> Result<[f32; N], A::Error> {
    let mut out = [0.0; N];
    for (i, slot) in out.iter_mut().enumerate() {
        match seq.next_element::<Num>()? {
            Some(Num(v)) => *slot = v,
            None => return Err(de::Error::custom(length_message(N, i))),
        }
    }
    let mut extra = 0;
    while seq.next_element::<de::IgnoredAny>()?.is_some() {
        extra += 1;
    }
    if extra > 0 {
        return Err(de::Error::custom(length_message(N, N + extra)));
    }
    Ok(out)
}

fn length_message(want: usize, got: usize) -> String {
    format!("expected an array of {want} numbers, found {got}")
}

/// An array of `N` finite numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct NumArray<const N: usize>(pub [f32; N]);

struct ArrayVisitor<const N: usize>;

impl<'de, const N: usize> Visitor<'de> for ArrayVisitor<N> {
    type Value = NumArray<N>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "an array of {N} numbers")
    }
    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<NumArray<N>, A::Error> {
        read_array(seq).map(NumArray)
    }
}

impl<'de, const N: usize> Deserialize<'de> for NumArray<N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_seq(ArrayVisitor::<N>)
    }
}

pub(crate) type V3 = NumArray<3>;
pub(crate) type V2 = NumArray<2>;

impl NumArray<3> {
    pub fn vec3(self) -> Vec3 {
        Vec3::from_array(self.0)
    }
}

impl NumArray<2> {
    pub fn vec2(self) -> Vec2 {
        Vec2::from_array(self.0)
    }
}

/// `[x, y, z]` or one number `s` meaning `[s, s, s]`: colours, intensities, scales.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Splat3(pub Vec3);

struct Splat3Visitor;

impl<'de> Visitor<'de> for Splat3Visitor {
    type Value = Splat3;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number or an array of 3 numbers")
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Splat3, E> {
        finite(v as f64).map(|Num(v)| Splat3(Vec3::splat(v)))
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Splat3, E> {
        finite(v as f64).map(|Num(v)| Splat3(Vec3::splat(v)))
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Splat3, E> {
        finite(v).map(|Num(v)| Splat3(Vec3::splat(v)))
    }
    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Splat3, A::Error> {
        read_array::<A, 3>(seq).map(|a| Splat3(Vec3::from_array(a)))
    }
}

impl<'de> Deserialize<'de> for Splat3 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(Splat3Visitor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[derive(Deserialize, Debug)]
    struct T {
        n: Option<Num>,
        v: Option<V3>,
        c: Option<Splat3>,
    }

    fn parse(s: &str) -> Result<T, String> {
        toml::from_str::<T>(s).map_err(|e| e.message().to_string())
    }

    #[test]
    fn numbers_accept_integers_and_floats() {
        assert_eq!(parse("n = 2").unwrap().n, Some(Num(2.0)));
        assert_eq!(parse("n = -0.5").unwrap().n, Some(Num(-0.5)));
        assert_eq!(
            parse("v = [1, 2.5, -3]").unwrap().v.unwrap().vec3(),
            Vec3::new(1.0, 2.5, -3.0)
        );
    }

    #[test]
    fn non_finite_and_out_of_range_numbers_are_rejected() {
        assert!(parse("n = nan").unwrap_err().contains("finite"));
        assert!(parse("n = -inf").unwrap_err().contains("finite"));
        assert!(parse("n = 1e300").unwrap_err().contains("out of range"));
        assert!(parse("v = [0, inf, 0]").unwrap_err().contains("finite"));
    }

    #[test]
    fn arrays_must_have_the_exact_length() {
        assert_eq!(parse("v = [1, 2]").unwrap_err(), length_message(3, 2));
        assert_eq!(
            parse("v = [1, 2, 3, 4, 5]").unwrap_err(),
            length_message(3, 5)
        );
        assert!(parse("v = 1").is_err());
        assert!(parse("v = [1, \"a\", 3]").is_err());
    }

    #[test]
    fn splat_takes_one_number_or_three() {
        assert_eq!(parse("c = 0.5").unwrap().c, Some(Splat3(Vec3::splat(0.5))));
        assert_eq!(parse("c = 2").unwrap().c, Some(Splat3(Vec3::splat(2.0))));
        assert_eq!(
            parse("c = [1, 2, 3]").unwrap().c,
            Some(Splat3(Vec3::new(1.0, 2.0, 3.0)))
        );
        assert!(parse("c = [1, 2]").is_err());
        assert!(parse("c = \"red\"").is_err());
    }
}
