//! The body of a PLY file, read straight into a [`MeshDesc`]'s flat arrays.
//!
//! `ply-rs` parses the header; this reads what follows it, binary (either byte order) or
//! ascii, element by element in the header's order, without a map or an allocation per
//! element: each property has a [`Slot`] decided once from its name, and each value goes
//! into its place in the mesh's vectors (or nowhere, for properties and elements
//! Candela does not use). Vectors are sized from the header's counts, which
//! [`super::ply`] has checked against the file's size first, so the mesh takes at most
//! 12 bytes a byte of the file (a binary `uchar` index becomes a third of a triangle's
//! `[u32; 3]`), and twice that while the index vector grows past its estimate.

use candela_core::color::srgb_decode;
use candela_core::desc::MeshDesc;
use glam::{Vec2, Vec3};
use ply_rs_bw::ply::{ElementDef, Encoding, Header, PropertyType, ScalarType};

/// Where one property's values go.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Slot {
    Skip,
    Position(usize),
    Normal(usize),
    Uv(usize),
    Color(usize),
    Indices,
}

/// The vertex attributes a header declares, by property name.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Attributes {
    pub normals: bool,
    pub uvs: bool,
    pub colors: bool,
}

/// The slots of the `vertex` element's properties: the first naming set found of each
/// attribute (as `ply.rs` documents them), the rest skipped.
pub(crate) fn vertex_slots(vertex: &ElementDef) -> (Vec<Slot>, Attributes) {
    let has = |names: &[&str]| names.iter().all(|n| vertex.properties.contains_key(*n));
    let uv = [
        ["u", "v"],
        ["s", "t"],
        ["texture_u", "texture_v"],
        ["texture_s", "texture_t"],
    ]
    .into_iter()
    .find(|uv| has(uv));
    let color = [["red", "green", "blue"], ["r", "g", "b"]]
        .into_iter()
        .find(|c| has(c));
    let normal = has(&["nx", "ny", "nz"]).then_some(["nx", "ny", "nz"]);
    let slots = vertex
        .properties
        .keys()
        .map(|name| {
            let at = |names: &[&str]| names.iter().position(|n| n == name);
            if let Some(i) = at(&["x", "y", "z"]) {
                Slot::Position(i)
            } else if let Some(i) = normal.and_then(|n| at(&n)) {
                Slot::Normal(i)
            } else if let Some(i) = uv.and_then(|n| at(&n)) {
                Slot::Uv(i)
            } else if let Some(i) = color.and_then(|n| at(&n)) {
                Slot::Color(i)
            } else {
                Slot::Skip
            }
        })
        .collect();
    let attributes = Attributes {
        normals: normal.is_some(),
        uvs: uv.is_some(),
        colors: color.is_some(),
    };
    (slots, attributes)
}

/// A problem in the body: its message, and for ascii files the line.
pub(crate) type BodyError = (Option<usize>, String);

/// One number of the body, with its declared type.
#[derive(Clone, Copy)]
struct Number {
    value: f64,
    ty: ScalarKind,
}

#[derive(Clone, Copy, PartialEq)]
enum ScalarKind {
    /// Signed or unsigned integers of up to 32 bits.
    Int,
    UChar,
    UShort,
    Float,
}

/// Reads numbers one after another from a binary or ascii body.
trait Numbers {
    /// The next number of type `t`, or why there is none.
    fn next(&mut self, t: &ScalarType) -> Result<Number, String>;
    /// Moves to the next element (the next line, in ascii).
    fn start_element(&mut self) -> Result<(), String>;
    /// The line being read, for ascii errors.
    fn line(&self) -> Option<usize>;
}

struct Binary<'a> {
    bytes: &'a [u8],
    at: usize,
    big_endian: bool,
}

impl Binary<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let end = self.at + N;
        let Some(b) = self.bytes.get(self.at..end) else {
            return Err(format!(
                "unexpected end of file at byte {} of the body",
                self.bytes.len()
            ));
        };
        self.at = end;
        let mut out: [u8; N] = b.try_into().expect("N bytes");
        if self.big_endian {
            out.reverse();
        }
        Ok(out)
    }
}

impl Numbers for Binary<'_> {
    #[inline]
    fn next(&mut self, t: &ScalarType) -> Result<Number, String> {
        use ScalarKind::*;
        let (value, ty) = match t {
            ScalarType::Char => (f64::from(i8::from_le_bytes(self.take()?)), Int),
            ScalarType::UChar => (f64::from(self.take::<1>()?[0]), UChar),
            ScalarType::Short => (f64::from(i16::from_le_bytes(self.take()?)), Int),
            ScalarType::UShort => (f64::from(u16::from_le_bytes(self.take()?)), UShort),
            ScalarType::Int => (f64::from(i32::from_le_bytes(self.take()?)), Int),
            ScalarType::UInt => (f64::from(u32::from_le_bytes(self.take()?)), Int),
            ScalarType::Float => (f64::from(f32::from_le_bytes(self.take()?)), Float),
            ScalarType::Double => (f64::from_le_bytes(self.take()?), Float),
        };
        Ok(Number { value, ty })
    }

    fn start_element(&mut self) -> Result<(), String> {
        Ok(())
    }

    fn line(&self) -> Option<usize> {
        None
    }
}

/// The body's lines, numbered from 0.
type Lines<'a> = std::iter::Enumerate<std::slice::Split<'a, u8, fn(&u8) -> bool>>;

struct Ascii<'a> {
    lines: Lines<'a>,
    tokens: std::str::SplitAsciiWhitespace<'a>,
    /// Lines before the body (the header's).
    first_line: usize,
    line: usize,
}

impl<'a> Ascii<'a> {
    fn new(body: &'a [u8], first_line: usize) -> Self {
        let newline: fn(&u8) -> bool = |&b| b == b'\n';
        Ascii {
            lines: body.split(newline).enumerate(),
            tokens: "".split_ascii_whitespace(),
            first_line,
            line: first_line,
        }
    }
}

impl Numbers for Ascii<'_> {
    fn next(&mut self, t: &ScalarType) -> Result<Number, String> {
        use ScalarKind::*;
        let Some(s) = self.tokens.next() else {
            return Err(format!("expected a {t:?} value, found the end of the line"));
        };
        let bad = || format!("`{s}` is not a {t:?} value");
        let (value, ty) = match t {
            ScalarType::Char => (f64::from(s.parse::<i8>().map_err(|_| bad())?), Int),
            ScalarType::UChar => (f64::from(s.parse::<u8>().map_err(|_| bad())?), UChar),
            ScalarType::Short => (f64::from(s.parse::<i16>().map_err(|_| bad())?), Int),
            ScalarType::UShort => (f64::from(s.parse::<u16>().map_err(|_| bad())?), UShort),
            ScalarType::Int => (f64::from(s.parse::<i32>().map_err(|_| bad())?), Int),
            ScalarType::UInt => (f64::from(s.parse::<u32>().map_err(|_| bad())?), Int),
            ScalarType::Float => (f64::from(s.parse::<f32>().map_err(|_| bad())?), Float),
            ScalarType::Double => (s.parse::<f64>().map_err(|_| bad())?, Float),
        };
        Ok(Number { value, ty })
    }

    fn start_element(&mut self) -> Result<(), String> {
        let Some((i, line)) = self.lines.next() else {
            return Err("unexpected end of file".into());
        };
        self.line = self.first_line + i + 1;
        let text = std::str::from_utf8(line).map_err(|_| "the line is not UTF-8".to_string())?;
        self.tokens = text.split_ascii_whitespace();
        Ok(())
    }

    fn line(&self) -> Option<usize> {
        Some(self.line)
    }
}

/// Reads the body of a file with this header into a mesh. `first_line` is the number of
/// lines the header takes (for ascii errors).
pub(crate) fn read_body(
    header: &Header,
    body: &[u8],
    first_line: usize,
) -> Result<MeshDesc, BodyError> {
    match header.encoding {
        Encoding::Ascii => read_elements(header, &mut Ascii::new(body, first_line)),
        Encoding::BinaryLittleEndian | Encoding::BinaryBigEndian => {
            let mut numbers = Binary {
                bytes: body,
                at: 0,
                big_endian: header.encoding == Encoding::BinaryBigEndian,
            };
            read_elements(header, &mut numbers)
        }
    }
}

fn read_elements(header: &Header, numbers: &mut impl Numbers) -> Result<MeshDesc, BodyError> {
    let mut mesh = MeshDesc::default();
    let vertices = header.elements.get("vertex").map_or(0, |v| v.count);
    for element in header.elements.values() {
        let (slots, attributes) = match element.name.as_str() {
            "vertex" => vertex_slots(element),
            "face" => (face_slots(element), Attributes::default()),
            _ => (
                vec![Slot::Skip; element.properties.len()],
                Attributes::default(),
            ),
        };
        if element.name == "vertex" {
            let n = element.count;
            mesh.positions.reserve_exact(n);
            mesh.normals
                .reserve_exact(if attributes.normals { n } else { 0 });
            mesh.uvs.reserve_exact(if attributes.uvs { n } else { 0 });
            mesh.colors
                .reserve_exact(if attributes.colors { n } else { 0 });
        } else if element.name == "face" {
            mesh.indices.reserve(element.count);
        }
        let types: Vec<&PropertyType> = element.properties.values().map(|p| &p.data_type).collect();
        let mut fan = Vec::new();
        for i in 0..element.count {
            let located = |m: String, numbers: &dyn Numbers| {
                (numbers.line(), format!("{} {i}: {m}", element.name))
            };
            numbers.start_element().map_err(|m| located(m, &*numbers))?;
            let mut position = Vec3::ZERO;
            let (mut normal, mut uv, mut color) = (Vec3::ZERO, Vec2::ZERO, Vec3::ZERO);
            for (slot, ty) in slots.iter().zip(&types) {
                let value = read_property(numbers, ty, *slot, &mut fan)
                    .map_err(|m| located(m, &*numbers))?;
                match (*slot, value) {
                    (Slot::Position(k), Some(v)) => position[k] = v,
                    (Slot::Normal(k), Some(v)) => normal[k] = v,
                    (Slot::Uv(k), Some(v)) => uv[k] = v,
                    (Slot::Color(k), Some(v)) => color[k] = v,
                    _ => {}
                }
            }
            match element.name.as_str() {
                "vertex" => {
                    mesh.positions.push(position);
                    if attributes.normals {
                        mesh.normals.push(normal);
                    }
                    if attributes.uvs {
                        mesh.uvs.push(uv);
                    }
                    if attributes.colors {
                        mesh.colors.push(color);
                    }
                }
                "face" => {
                    if fan.len() < 3 {
                        return Err(located(format!("has {} vertices", fan.len()), &*numbers));
                    }
                    if let Some(v) = fan.iter().find(|&&v| v as usize >= vertices) {
                        let m = format!("vertex index {v} out of range ({vertices} vertices)");
                        return Err(located(m, &*numbers));
                    }
                    mesh.indices
                        .extend((1..fan.len() - 1).map(|k| [fan[0], fan[k], fan[k + 1]]));
                }
                _ => {}
            }
        }
    }
    Ok(mesh)
}

/// The face element's slots: its index list (the first of `vertex_indices` and
/// `vertex_index` it has), the rest skipped.
fn face_slots(face: &ElementDef) -> Vec<Slot> {
    let name = ["vertex_indices", "vertex_index"]
        .into_iter()
        .find(|n| face.properties.contains_key(*n));
    face.properties
        .keys()
        .map(|k| {
            if Some(k.as_str()) == name {
                Slot::Indices
            } else {
                Slot::Skip
            }
        })
        .collect()
}

/// Reads one property into its slot: a scalar's value as f32 (a colour channel decoded,
/// see `ply::color_channel`), an index list into `fan`.
#[inline]
fn read_property(
    numbers: &mut impl Numbers,
    ty: &PropertyType,
    slot: Slot,
    fan: &mut Vec<u32>,
) -> Result<Option<f32>, String> {
    match ty {
        PropertyType::Scalar(t) => {
            let n = numbers.next(t)?;
            Ok(match slot {
                Slot::Skip => None,
                Slot::Color(_) => Some(color_channel(n).ok_or("colours must be numbers")?),
                _ => Some(n.value as f32),
            })
        }
        PropertyType::List(count, t) => {
            let c = numbers.next(count)?;
            if c.ty == ScalarKind::Float || c.value < 0.0 {
                return Err(format!("list count {} is not a count", c.value));
            }
            fan.clear();
            for _ in 0..c.value as u64 {
                let n = numbers.next(t)?;
                if slot == Slot::Indices {
                    if n.ty == ScalarKind::Float || n.value < 0.0 {
                        return Err(format!(
                            "vertex index {} is not a non-negative integer",
                            n.value
                        ));
                    }
                    fan.push(n.value as u32);
                }
            }
            Ok(None)
        }
    }
}

/// A vertex colour channel as linear light: 8- and 16-bit integers are sRGB-encoded, as
/// scanners and Blender write them (so decoded, as Candela's image textures are), floats
/// are taken as linear values; other integers are no colours.
fn color_channel(n: Number) -> Option<f32> {
    let encoded = |max: f64| srgb_decode((n.value / max).clamp(0.0, 1.0) as f32);
    match n.ty {
        ScalarKind::UChar => Some(encoded(255.0)),
        ScalarKind::UShort => Some(encoded(65535.0)),
        ScalarKind::Float => Some((n.value as f32).max(0.0)),
        ScalarKind::Int => None,
    }
}
