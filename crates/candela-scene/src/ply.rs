//! Stanford PLY meshes (ascii and binary) through `ply-rs-bw`: a `vertex` element with
//! `x y z`, optional `nx ny nz`, uvs (`u v`, `s t` or `texture_u texture_v`) and colours
//! (`red green blue` or `r g b`: 8- and 16-bit channels sRGB-decoded, floats linear), and a
//! `face` element whose `vertex_indices` (or `vertex_index`) lists are triangulated as
//! fans. Counts declared in the header are checked against the file size before anything
//! is read, so a truncated or hostile file cannot ask for a huge allocation. `ply-rs`
//! reads the header; [`crate::ply_body`] reads the body straight into the mesh's arrays.

use std::io::Cursor;
use std::path::Path;

use candela_core::desc::MeshDesc;
use ply_rs_bw::parser::{ParseError, Parser, Reader};
use ply_rs_bw::ply::{DefaultElement, ElementDef, Encoding, Header, PropertyType, ScalarType};

use crate::ply_body::read_body;
use crate::MeshError;

/// Loads a PLY file into one mesh.
pub fn load_ply(path: &Path) -> Result<MeshDesc, MeshError> {
    let bytes =
        std::fs::read(path).map_err(|e| MeshError::new(path, None, format!("cannot read: {e}")))?;
    parse_ply(&bytes, path)
}

/// Parses the bytes of a PLY file; `path` names the file in errors.
pub fn parse_ply(bytes: &[u8], path: &Path) -> Result<MeshDesc, MeshError> {
    let err = |line: Option<usize>, message: String| MeshError::new(path, line, message);
    let parser = Parser::<DefaultElement>::new();
    let mut reader = Reader::new(Cursor::new(bytes));
    let header = parser
        .read_header(&mut reader)
        .map_err(|e| err(e.line(), one_line(&e)))?;
    let body = bytes.len() - reader.get_ref().position() as usize;
    check_sizes(&header, body).map_err(|m| err(None, m))?;

    let vertex = header
        .elements
        .get("vertex")
        .ok_or_else(|| err(None, "PLY file has no `vertex` element".into()))?;
    let face = header
        .elements
        .get("face")
        .ok_or_else(|| err(None, "PLY file has no `face` element".into()))?;
    if !["x", "y", "z"]
        .iter()
        .all(|n| vertex.properties.contains_key(*n))
    {
        return Err(err(None, "PLY `vertex` element lacks x, y or z".into()));
    }
    if !["vertex_indices", "vertex_index"]
        .iter()
        .any(|n| face.properties.contains_key(*n))
    {
        return Err(err(
            None,
            "PLY `face` element has no `vertex_indices` or `vertex_index` list".into(),
        ));
    }

    let start = bytes.len() - body;
    let header_lines = bytes[..start].iter().filter(|&&b| b == b'\n').count();
    let mesh = read_body(&header, &bytes[start..], header_lines)
        .map_err(|(line, message)| err(line, message))?;
    if mesh.indices.is_empty() {
        return Err(err(None, "PLY file has no faces".into()));
    }
    Ok(mesh)
}

/// The parser's message on one line, without its own "Line N: " prefix.
fn one_line(e: &ParseError) -> String {
    let text = e.to_string();
    let text = match e.line() {
        Some(line) => text
            .strip_prefix(&format!("Line {line}: "))
            .unwrap_or(&text)
            .to_string(),
        None => text,
    };
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

fn scalar_size(t: &ScalarType) -> u64 {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// The fewest bytes one element can take: binary scalars at their size and lists at the
/// size of their (possibly zero) count; ascii at least one character and one separator
/// per property.
fn min_element_size(element: &ElementDef, encoding: Encoding) -> u64 {
    match encoding {
        Encoding::Ascii => 2 * element.properties.len() as u64,
        _ => element
            .properties
            .values()
            .map(|p| match &p.data_type {
                PropertyType::Scalar(t) => scalar_size(t),
                PropertyType::List(count, _) => scalar_size(count),
            })
            .sum(),
    }
}

/// Rejects a header whose element counts cannot fit in the `body` bytes that follow it.
fn check_sizes(header: &Header, body: usize) -> Result<(), String> {
    let mut need: u128 = 0;
    for element in header.elements.values() {
        if element.properties.is_empty() && element.count > 0 {
            // Costs no bytes per element, so its count is bounded by nothing.
            return Err(format!("PLY element `{}` has no properties", element.name));
        }
        need += element.count as u128 * min_element_size(element, header.encoding) as u128;
    }
    // An ascii file's last line may lack its newline.
    let slack = u128::from(header.encoding == Encoding::Ascii);
    if need > body as u128 + slack {
        let counts: Vec<String> = header
            .elements
            .values()
            .map(|e| format!("{} {}", e.count, e.name))
            .collect();
        return Err(format!(
            "PLY header declares {} (at least {need} bytes) but only {body} bytes follow it; \
             the file is truncated or corrupt",
            counts.join(", ")
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec3};

    fn parse(bytes: &[u8]) -> Result<MeshDesc, MeshError> {
        parse_ply(bytes, Path::new("m.ply"))
    }

    const ASCII_QUAD: &str = "ply\nformat ascii 1.0\ncomment a unit quad\n\
        element vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
        property float nx\nproperty float ny\nproperty float nz\n\
        property float s\nproperty float t\n\
        element face 1\nproperty list uchar int vertex_indices\nend_header\n\
        0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n1 1 0 0 0 1 1 1\n0 1 0 0 0 1 0 1\n4 0 1 2 3\n";

    #[test]
    fn ascii_polygons_become_fans_with_normals_and_uvs() {
        let mesh = parse(ASCII_QUAD.as_bytes()).unwrap();
        assert_eq!(mesh.positions.len(), 4);
        assert_eq!(mesh.indices, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(mesh.normals, vec![Vec3::Z; 4]);
        for (p, uv) in mesh.positions.iter().zip(&mesh.uvs) {
            assert_eq!(p.truncate(), *uv);
        }
    }

    /// A binary PLY of one triangle (positions as doubles, `vertex_index` with uint
    /// counts), in either byte order.
    fn binary_triangle(big_endian: bool) -> Vec<u8> {
        let format = if big_endian {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        };
        let mut bytes = format!(
            "ply\nformat {format} 1.0\nelement vertex 3\nproperty double x\n\
             property double y\nproperty double z\nproperty float u\nproperty float v\n\
             element face 1\nproperty list uint int vertex_index\nend_header\n"
        )
        .into_bytes();
        let f64b = |v: f64| {
            if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        };
        let f32b = |v: f32| {
            if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        };
        let u32b = |v: u32| {
            if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        };
        for p in [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0]] {
            for c in p {
                bytes.extend(f64b(c));
            }
            bytes.extend(f32b(p[0] as f32));
            bytes.extend(f32b(p[1] as f32));
        }
        bytes.extend(u32b(3));
        for i in [0u32, 1, 2] {
            bytes.extend(u32b(i));
        }
        bytes
    }

    #[test]
    fn vertex_colours_are_decoded_to_linear_light() {
        let header = |ty: &str| {
            format!(
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                 property float z\nproperty {ty} red\nproperty {ty} green\nproperty {ty} blue\n\
                 element face 1\nproperty list uchar int vertex_indices\nend_header\n"
            )
        };
        // 8- and 16-bit colours are sRGB: 255 is 1, 128 (or 32896) is 0.2158.
        let bytes = header("uchar") + "0 0 0 255 128 0\n1 0 0 0 0 0\n0 1 0 1 1 1\n3 0 1 2\n";
        let mesh = parse(bytes.as_bytes()).unwrap();
        assert!((mesh.colors[0] - Vec3::new(1.0, 0.215_861, 0.0)).length() < 1e-5);
        assert_eq!(mesh.colors.len(), 3);
        let bytes = header("ushort") + "0 0 0 65535 32896 0\n1 0 0 0 0 0\n0 1 0 1 1 1\n3 0 1 2\n";
        let mesh = parse(bytes.as_bytes()).unwrap();
        assert!((mesh.colors[0] - Vec3::new(1.0, 0.215_861, 0.0)).length() < 1e-5);
        // Floats are linear already.
        let bytes = header("float") + "0 0 0 0.25 0.5 1\n1 0 0 0 0 0\n0 1 0 1 1 1\n3 0 1 2\n";
        let mesh = parse(bytes.as_bytes()).unwrap();
        assert_eq!(mesh.colors[0], Vec3::new(0.25, 0.5, 1.0));
        // Without colours there are none.
        assert!(parse(ASCII_QUAD.as_bytes()).unwrap().colors.is_empty());
    }

    #[test]
    fn binary_files_of_both_byte_orders_load() {
        for big_endian in [false, true] {
            let mesh = parse(&binary_triangle(big_endian)).unwrap();
            assert_eq!(mesh.positions[2], Vec3::new(0.0, 2.0, 0.0));
            assert_eq!(mesh.uvs[1], Vec2::new(1.0, 0.0));
            assert!(mesh.normals.is_empty());
            assert_eq!(mesh.indices, vec![[0, 1, 2]]);
        }
    }

    #[test]
    fn every_truncation_of_a_binary_file_is_an_error() {
        let bytes = binary_triangle(false);
        for len in 0..bytes.len() {
            assert!(parse(&bytes[..len]).is_err(), "truncated to {len} bytes");
        }
    }

    #[test]
    fn huge_declared_counts_are_rejected_before_reading() {
        let text = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n\
            property float x\nproperty float y\nproperty float z\n\
            element face 1\nproperty list uchar int vertex_indices\nend_header\n\0\0\0\0";
        let e = parse(text.as_bytes()).unwrap_err();
        assert!(e.message.contains("truncated or corrupt"), "{e}");
        assert!(e.to_string().starts_with("m.ply: "), "{e}");
    }

    #[test]
    fn an_element_without_properties_is_an_error() {
        let text = "ply\nformat binary_little_endian 1.0\nelement junk 4000000000\n\
            element vertex 0\nproperty float x\nend_header\n";
        let e = parse(text.as_bytes()).unwrap_err();
        assert_eq!(e.to_string(), "m.ply: PLY element `junk` has no properties");
    }

    #[test]
    fn a_huge_list_count_is_an_error() {
        let mut bytes = binary_triangle(false);
        let at = bytes.len() - 16; // the face's list count
        bytes[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(parse(&bytes).is_err());
    }

    #[test]
    fn malformed_files_are_errors() {
        let quad = ASCII_QUAD;
        let cases = [
            ("not a ply file".to_string(), ""),
            (quad.replace("4 0 1 2 3", "4 0 1 2 9"), "out of range"),
            (quad.replace("4 0 1 2 3", "2 0 1"), "has 2 vertices"),
            (quad.replace("4 0 1 2 3", "3 0 -1 2"), "face 0"),
            (quad.replace("1 1 0 0 0 1 1 1", "1 x 0 0 0 1 1 1"), ""),
            (quad.replace("element face 1", "element face 0"), "no faces"),
            (quad.replace("vertex_indices", "corners"), "vertex_indices"),
            (quad.replace("property float z\n", ""), "x, y or z"),
        ];
        for (text, needle) in cases {
            let e = parse(text.as_bytes()).unwrap_err();
            assert!(e.message.contains(needle), "{e}");
            assert!(!e.message.contains('\n'), "{e:?}");
        }
    }

    #[test]
    fn ascii_errors_name_the_line() {
        let text = ASCII_QUAD.replace("1 1 0 0 0 1 1 1", "1 x 0 0 0 1 1 1");
        let e = parse(text.as_bytes()).unwrap_err();
        // The header takes 15 lines; the bad vertex is the third after it.
        assert_eq!(e.line, Some(18), "{e}");
    }

    /// Every prefix of an ascii file, and every byte of ascii and binary files changed
    /// to a few values, gives a mesh or a one-line error, never a panic; a changed
    /// byte in the binary body still gives a mesh of the same size or an error.
    #[test]
    fn truncated_and_flipped_files_are_meshes_or_errors() {
        let ascii = ASCII_QUAD.as_bytes();
        for len in 0..ascii.len() - 1 {
            if let Err(e) = parse(&ascii[..len]) {
                assert!(!e.message.contains('\n'), "{e:?}");
            }
        }
        for file in [
            ascii.to_vec(),
            binary_triangle(false),
            binary_triangle(true),
        ] {
            for at in 0..file.len() {
                for x in [0x01u8, 0x20, 0x80, 0xff] {
                    let mut bytes = file.clone();
                    bytes[at] ^= x;
                    match parse(&bytes) {
                        Ok(mesh) => assert!(mesh.indices.len() <= 2, "byte {at} ^ {x:#x}"),
                        Err(e) => assert!(!e.message.contains('\n'), "{e:?}"),
                    }
                }
            }
        }
    }

    #[test]
    fn binary_polygons_and_extra_elements_are_read_in_order() {
        // A comment element before the vertices, an extra face property after the list.
        let mut bytes = b"ply\nformat binary_big_endian 1.0\nelement note 2\nproperty short k\n\
            element vertex 4\nproperty float x\nproperty uchar flag\nproperty float y\n\
            property float z\nelement face 1\nproperty list uchar ushort vertex_indices\n\
            property int tag\nend_header\n"
            .to_vec();
        bytes.extend([0, 1, 0, 2]);
        for p in [
            [0.0f32, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.5],
        ] {
            bytes.extend(p[0].to_be_bytes());
            bytes.push(7);
            bytes.extend(p[1].to_be_bytes());
            bytes.extend(p[2].to_be_bytes());
        }
        bytes.push(4);
        for i in [0u16, 1, 2, 3] {
            bytes.extend(i.to_be_bytes());
        }
        bytes.extend(9i32.to_be_bytes());
        let mesh = parse(&bytes).unwrap();
        assert_eq!(mesh.positions[3], Vec3::new(0.0, 1.0, 0.5));
        assert_eq!(mesh.indices, vec![[0, 1, 2], [0, 2, 3]]);
    }
}
