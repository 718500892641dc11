//! Mitsuba's `serialized` meshes: files written here byte by byte as its format
//! describes, read by the importer, and compared with what Mitsuba 3.9.1 reads from the
//! same bytes (`mi.load_dict({'type': 'serialized', 'filename': F, 'shape_index': I})`,
//! then `vertex_positions_buffer()`, `vertex_normals_buffer()`, `faces_buffer()`).

use std::io::Write;

use candela_core::desc::{GeometryDesc, MeshDesc};
use candela_scene::mitsuba::serialized::load_serialized;
use candela_scene::{load_scene_with, LoadOptions};
use flate2::write::ZlibEncoder;
use glam::{Vec2, Vec3};

/// One mesh: the header, then the zlib stream (f32 or f64, optional normals and uvs).
fn mesh_bytes(version: u16, mesh: &MeshDesc, double: bool) -> Vec<u8> {
    let mut flags = if double { 0x2000u32 } else { 0x1000 };
    if !mesh.normals.is_empty() {
        flags |= 0x1;
    }
    if !mesh.uvs.is_empty() {
        flags |= 0x2;
    }
    let mut raw = flags.to_le_bytes().to_vec();
    if version == 4 {
        raw.extend_from_slice(b"mesh\0");
    }
    raw.extend((mesh.positions.len() as u64).to_le_bytes());
    raw.extend((mesh.indices.len() as u64).to_le_bytes());
    let reals = mesh
        .positions
        .iter()
        .chain(&mesh.normals)
        .flat_map(|v| v.to_array())
        .chain(mesh.uvs.iter().flat_map(|v| v.to_array()));
    for x in reals {
        match double {
            true => raw.extend((x as f64).to_le_bytes()),
            false => raw.extend(x.to_le_bytes()),
        }
    }
    for i in mesh.indices.iter().flatten() {
        raw.extend(i.to_le_bytes());
    }
    let mut z = ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    z.write_all(&raw).unwrap();
    let mut out = 0x041Cu16.to_le_bytes().to_vec();
    out.extend(version.to_le_bytes());
    out.extend(z.finish().unwrap());
    out
}

/// A file of meshes with its dictionary of offsets.
fn file_bytes(version: u16, meshes: &[(MeshDesc, bool)]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut offsets = Vec::new();
    for (mesh, double) in meshes {
        offsets.push(out.len() as u64);
        out.extend(mesh_bytes(version, mesh, *double));
    }
    for o in &offsets {
        match version {
            4 => out.extend(o.to_le_bytes()),
            _ => out.extend((*o as u32).to_le_bytes()),
        }
    }
    out.extend((meshes.len() as u32).to_le_bytes());
    out
}

/// A bent quad with uvs and no normals, and a tetrahedron with normals (0, 0, 1).
fn quad_and_tetrahedron() -> (MeshDesc, MeshDesc) {
    let quad = MeshDesc {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.5), Vec3::Y],
        uvs: vec![Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        ..Default::default()
    };
    let tetrahedron = MeshDesc {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
        normals: vec![Vec3::Z; 4],
        indices: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        ..Default::default()
    };
    (quad, tetrahedron)
}

fn mitsuba_mesh(dir: &std::path::Path, shape: &str) -> Result<MeshDesc, String> {
    let xml = format!("<scene version=\"3.0.0\">{shape}</scene>");
    std::fs::write(dir.join("scene.xml"), xml).unwrap();
    let loaded = load_scene_with(&dir.join("scene.xml"), &LoadOptions::default())
        .map_err(|e| e.to_string())?;
    match &loaded.desc.shapes[0].geometry {
        GeometryDesc::Mesh(m) => Ok(m.as_ref().clone()),
        g => panic!("{g:?}"),
    }
}

fn assert_close(a: &[Vec3], b: &[[f32; 3]]) {
    assert_eq!(a.len(), b.len());
    for (a, b) in a.iter().zip(b) {
        assert!(
            (*a - Vec3::from(*b)).abs().max_element() < 1e-6,
            "{a} vs {b:?}"
        );
    }
}

#[test]
fn serialized_meshes_read_as_mitsuba_reads_them() {
    let dir = tempfile::tempdir().unwrap();
    let (quad, tetrahedron) = quad_and_tetrahedron();
    std::fs::write(
        dir.path().join("two.serialized"),
        file_bytes(4, &[(quad.clone(), false), (tetrahedron.clone(), true)]),
    )
    .unwrap();
    std::fs::write(
        dir.path().join("v3.serialized"),
        file_bytes(3, &[(quad.clone(), false)]),
    )
    .unwrap();

    // The quad without normals gets Mitsuba's angle-weighted vertex normals; its uvs
    // stay as stored (no flip, unlike an OBJ's).
    let mitsuba_normals = [
        [-0.235702, -0.235702, 0.942809],
        [0.0, -0.447214, 0.894427],
        [-0.235702, -0.235702, 0.942809],
        [-0.447214, 0.0, 0.894427],
    ];
    for (file, index) in [("two.serialized", ""), ("v3.serialized", "")] {
        let m = mitsuba_mesh(
            dir.path(),
            &format!(r#"<shape type="serialized"><string name="filename" value="{file}"/>{index}</shape>"#),
        )
        .unwrap();
        assert_eq!(m.positions, quad.positions, "{file}");
        assert_eq!(m.indices, quad.indices, "{file}");
        assert_close(&m.normals, &mitsuba_normals);
        if file == "two.serialized" {
            assert_eq!(m.uvs, quad.uvs);
        }
    }
    // The second mesh, stored in double precision, keeps its own normals.
    let m = mitsuba_mesh(
        dir.path(),
        r#"<shape type="serialized"><string name="filename" value="two.serialized"/>
             <integer name="shape_index" value="1"/></shape>"#,
    )
    .unwrap();
    assert_eq!(m.positions, tetrahedron.positions);
    assert_eq!(m.indices, tetrahedron.indices);
    assert_eq!(m.normals, tetrahedron.normals);
    // face_normals drops them.
    let m = mitsuba_mesh(
        dir.path(),
        r#"<shape type="serialized"><string name="filename" value="two.serialized"/>
             <integer name="shape_index" value="1"/><boolean name="face_normals" value="true"/></shape>"#,
    )
    .unwrap();
    assert!(m.normals.is_empty());

    let e = mitsuba_mesh(
        dir.path(),
        r#"<shape type="serialized"><string name="filename" value="two.serialized"/>
             <integer name="shape_index" value="2"/></shape>"#,
    )
    .unwrap_err();
    assert!(
        e.contains("scene.xml:1:")
            && e.contains("shape_index 2 is out of range: the file holds 2 mesh(es)"),
        "{e}"
    );
}

#[test]
fn a_broken_serialized_file_is_an_error_never_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let (quad, tetrahedron) = quad_and_tetrahedron();
    let good = file_bytes(4, &[(quad, false), (tetrahedron, true)]);
    let path = dir.path().join("m.serialized");
    // Every prefix of the file, and the file with each byte in turn flipped: each loads
    // both meshes or fails with a message.
    let mut failures = 0;
    for variant in (0..good.len())
        .map(|n| good[..n].to_vec())
        .chain((0..good.len()).map(|i| {
            let mut b = good.clone();
            b[i] ^= 0xa5;
            b
        }))
    {
        std::fs::write(&path, &variant).unwrap();
        for index in 0..2 {
            match load_serialized(&path, index) {
                Ok(m) => assert!(m
                    .indices
                    .iter()
                    .flatten()
                    .all(|&i| (i as usize) < m.positions.len())),
                Err(e) => {
                    assert!(!e.message.is_empty());
                    failures += 1;
                }
            }
        }
    }
    assert!(failures > good.len(), "{failures} failures");
    // A header that is not Mitsuba's.
    std::fs::write(&path, b"PLY\n0123456789").unwrap();
    let e = load_serialized(&path, 0).unwrap_err().to_string();
    assert!(e.contains("not a Mitsuba serialized mesh"), "{e}");
    // Counts the file's size cannot hold are refused before anything is allocated.
    let mut raw = 0x1000u32.to_le_bytes().to_vec();
    raw.extend(b"x\0");
    raw.extend(u64::MAX.to_le_bytes());
    raw.extend(1u64.to_le_bytes());
    let mut z = ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    z.write_all(&raw).unwrap();
    let mut bytes = 0x041Cu16.to_le_bytes().to_vec();
    bytes.extend(4u16.to_le_bytes());
    bytes.extend(z.finish().unwrap());
    bytes.extend(0u64.to_le_bytes());
    bytes.extend(1u32.to_le_bytes());
    std::fs::write(&path, &bytes).unwrap();
    let e = load_serialized(&path, 0).unwrap_err().to_string();
    assert!(e.contains("do not fit what the file's size allows"), "{e}");
}
