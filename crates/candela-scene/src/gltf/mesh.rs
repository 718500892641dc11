//! glTF meshes: each primitive becomes one shared [`MeshDesc`] (one `Arc` per primitive,
//! whichever nodes place it) and one [`ShapeDesc`] per placement.
//!
//! - Topology: triangles, triangle strips (triangle i is (i, i+1, i+2) with the first two
//!   swapped on odd i, glTF 2.0 §3.7.2.1) and fans ((i+1, i+2, 0)); points and lines are
//!   skipped with a warning. Without indices the vertices are taken in order.
//! - Normals: read where given; where missing they are left out, and the renderer shades
//!   with the triangle's geometric normal — the flat normals glTF prescribes.
//! - Vertex colours: COLOR_0's RGB (float or normalized u8/u16, linear) multiplies the
//!   base colour; its alpha is not read (a warning says so where it is below 1).
//! - Texture coordinates: the set (TEXCOORD_0 or _1) that the material's textures name,
//!   with v flipped (glTF's v runs down the image, Candela's up).
//! - Tangents: TANGENT is read where the material has a normal map (bitangent
//!   w·(n × t), glTF 2.0 §3.7.2.1). Where it is missing, the renderer generates the frame
//!   per triangle from the uvs: t = ∂p/∂u, and the bitangent's sign is that of
//!   (ng × ∂p/∂u)·∂p/∂v, so mirrored-uv regions get the right one. Not smoothed per vertex
//!   and not MikkTSpace: per-triangle frames need no vertex splitting at mirror seams and
//!   no dependency, at the cost of faceted tangents on curved low-poly meshes.

use std::collections::HashMap;
use std::sync::Arc;

use candela_core::desc::{GeometryDesc, MeshDesc, ShapeDesc};
use glam::{Mat4, Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use super::material::Materials;
use super::{Ctx, GltfScene};
use crate::LoadError;

/// Primitives already converted, by (mesh, primitive) index.
#[derive(Default)]
pub(crate) struct MeshCache {
    prims: HashMap<(usize, usize), Option<Arc<MeshDesc>>>,
}

/// Places every primitive of `mesh` with the node's world transform.
pub(crate) fn place_mesh(
    ctx: &mut Ctx,
    cache: &mut MeshCache,
    materials: &mut Materials,
    out: &mut GltfScene,
    mesh: &gltf::Mesh,
    world: Mat4,
) -> Result<(), LoadError> {
    for prim in mesh.primitives() {
        let mat = materials.get(ctx, &prim.material())?;
        let key = (mesh.index(), prim.index());
        let desc = match cache.prims.get(&key) {
            Some(d) => d.clone(),
            None => {
                let path = format!("meshes[{}].primitives[{}]", mesh.index(), prim.index());
                let d = read_primitive(ctx, &prim, mat.tex_coord, mat.has_normal_map, &path)?
                    .map(Arc::new);
                if prim.morph_targets().next().is_some() {
                    ctx.warn(format!("{path}: morph targets are ignored"));
                }
                cache.prims.insert(key, d.clone());
                d
            }
        };
        if let Some(desc) = desc {
            // A mirroring transform makes the front faces clockwise (glTF 2.0 §3.7.2.1).
            // The renderer takes the front from the winding of the world-space vertices,
            // which a mirror reverses; shading normals, where given, already decide it.
            let flip_normals = world.determinant() < 0.0 && desc.normals.is_empty();
            out.shapes.push(ShapeDesc {
                geometry: GeometryDesc::Mesh(desc),
                material: mat.name.clone(),
                emission: mat.emission,
                emission_texture: mat.emission_texture.clone(),
                transform: world,
                flip_normals,
                span: ctx.span(),
            });
        }
    }
    Ok(())
}

/// Why an accessor could not be read.
fn unreadable(ctx: &Ctx, path: &str, what: &str, accessor: &gltf::Accessor) -> LoadError {
    let detail = match accessor.view() {
        None if accessor.sparse().is_none() => "has no buffer view".to_string(),
        None => format!(
            "accessor {}'s sparse indices or values read past the end of their buffer views",
            accessor.index()
        ),
        Some(v) => format!(
            "accessor {} reads past the end of buffer view {} or buffer {}",
            accessor.index(),
            v.index(),
            v.buffer().index()
        ),
    };
    ctx.error(path, format!("{what}: {detail}"))
}

/// The element formats glTF 2.0 §3.7.2.1 allows for each attribute the importer reads
/// (KHR_mesh_quantization's others are refused with the extension).
const FLOAT: &[DataType] = &[DataType::F32];
const FLOAT_OR_UNORM: &[DataType] = &[DataType::F32, DataType::U8, DataType::U16];
const INDEX: &[DataType] = &[DataType::U8, DataType::U16, DataType::U32];

/// Checks what the `gltf` crate's readers assume without checking (they panic or misread
/// otherwise): the element format, a non-zero count, and strides no shorter than an
/// element.
fn check_accessor(
    ctx: &Ctx,
    path: &str,
    what: &str,
    accessor: &gltf::Accessor,
    dims: &[Dimensions],
    types: &[DataType],
) -> Result<(), LoadError> {
    let at = format!("{what}: accessors[{}]", accessor.index());
    let (d, t) = (accessor.dimensions(), accessor.data_type());
    if !dims.contains(&d) || !types.contains(&t) {
        return Err(ctx.error(
            path,
            format!("{at} holds {d:?} of {t:?}; glTF allows {dims:?} of {types:?} here"),
        ));
    }
    if accessor.count() == 0 {
        return Err(ctx.error(path, format!("{at} has count 0 (at least 1 is required)")));
    }
    let short = |view: gltf::buffer::View, size: usize| {
        view.stride().filter(|&s| s < size).map(|s| {
            format!(
                "buffer view {} has byteStride {s} < the element's {size} bytes",
                view.index()
            )
        })
    };
    let mut problem = accessor.view().and_then(|v| short(v, accessor.size()));
    if let Some(sparse) = accessor.sparse() {
        if sparse.count() == 0 {
            return Err(ctx.error(path, format!("{at}: sparse count is 0 (at least 1)")));
        }
        let indices = sparse.indices();
        problem = problem
            .or_else(|| short(indices.view(), indices.index_type().size()))
            .or_else(|| short(sparse.values().view(), accessor.size()));
    }
    match problem {
        Some(p) => Err(ctx.error(path, format!("{at}: {p}"))),
        None => Ok(()),
    }
}

/// The primitive as a mesh in object space, or `None` where it has no triangles.
fn read_primitive(
    ctx: &mut Ctx,
    prim: &gltf::Primitive,
    tex_coord: u32,
    normal_map: bool,
    path: &str,
) -> Result<Option<MeshDesc>, LoadError> {
    let mode = prim.mode();
    if !matches!(
        mode,
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
    ) {
        ctx.warn(format!("{path}: {mode:?} primitives are skipped"));
        return Ok(None);
    }
    let buffers = &ctx.buffers;
    let reader = prim.reader(|b| buffers.get(b.index()).map(|d| d.0.as_slice()));
    let Some(pos_accessor) = prim.get(&gltf::Semantic::Positions) else {
        return Err(ctx.error(path, "has no POSITION attribute"));
    };
    use Dimensions::{Scalar, Vec2 as V2, Vec3 as V3, Vec4 as V4};
    let attribute = |s: gltf::Semantic| prim.get(&s).map(|a| (s, a));
    for (semantic, a) in [
        attribute(gltf::Semantic::Positions),
        attribute(gltf::Semantic::Normals),
        attribute(gltf::Semantic::TexCoords(tex_coord)),
        attribute(gltf::Semantic::Colors(0)),
    ]
    .into_iter()
    .flatten()
    .chain(
        normal_map
            .then(|| attribute(gltf::Semantic::Tangents))
            .flatten(),
    ) {
        let (dims, types): (&[Dimensions], _) = match semantic {
            gltf::Semantic::Positions | gltf::Semantic::Normals => (&[V3], FLOAT),
            gltf::Semantic::Tangents => (&[V4], FLOAT),
            gltf::Semantic::TexCoords(_) => (&[V2], FLOAT_OR_UNORM),
            _ => (&[V3, V4], FLOAT_OR_UNORM),
        };
        check_accessor(ctx, path, &semantic.to_string(), &a, dims, types)?;
    }
    if let Some(a) = prim.indices() {
        check_accessor(ctx, path, "indices", &a, &[Scalar], INDEX)?;
    }
    let positions: Vec<Vec3> = match reader.read_positions() {
        Some(it) => it.map(Vec3::from).collect(),
        None => return Err(unreadable(ctx, path, "POSITION", &pos_accessor)),
    };
    let n = positions.len();
    let normals: Vec<Vec3> = match prim.get(&gltf::Semantic::Normals) {
        None => Vec::new(),
        Some(a) => match reader.read_normals() {
            Some(it) => it.map(Vec3::from).collect(),
            None => return Err(unreadable(ctx, path, "NORMAL", &a)),
        },
    };
    let uvs: Vec<Vec2> = match prim.get(&gltf::Semantic::TexCoords(tex_coord)) {
        None => Vec::new(),
        Some(a) => match reader.read_tex_coords(tex_coord) {
            Some(it) => it.into_f32().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect(),
            None => return Err(unreadable(ctx, path, &format!("TEXCOORD_{tex_coord}"), &a)),
        },
    };
    // COLOR_0 (RGB or RGBA, float or normalized u8/u16) is linear; the crate decodes it.
    let mut colors: Vec<Vec3> = Vec::new();
    let mut translucent = false;
    if let Some(a) = prim.get(&gltf::Semantic::Colors(0)) {
        let Some(it) = reader.read_colors(0) else {
            return Err(unreadable(ctx, path, "COLOR_0", &a));
        };
        colors = it
            .into_rgba_f32()
            .map(|[r, g, b, alpha]| {
                translucent |= alpha < 1.0;
                Vec3::new(r, g, b)
            })
            .collect();
    }
    // TANGENT only matters to a normal map.
    let tangents: Vec<Vec4> = match prim.get(&gltf::Semantic::Tangents) {
        Some(a) if normal_map => match reader.read_tangents() {
            Some(it) => it.map(Vec4::from).collect(),
            None => return Err(unreadable(ctx, path, "TANGENT", &a)),
        },
        _ => Vec::new(),
    };
    for (what, len) in [
        ("NORMAL", normals.len()),
        ("TANGENT", tangents.len()),
        ("TEXCOORD", uvs.len()),
        ("COLOR_0", colors.len()),
    ] {
        if len != 0 && len != n {
            return Err(ctx.error(path, format!("{what} has {len} elements for {n} positions")));
        }
    }
    let indices = match (mode, prim.indices()) {
        // Straight into triangles, without the list of indices beside them.
        (Mode::Triangles, Some(a)) => match reader.read_indices() {
            Some(it) => {
                let mut tris = Vec::with_capacity(a.count() / 3);
                let (mut corners, mut k) = ([0; 3], 0);
                for i in it.into_u32() {
                    check_indices(ctx, path, [&i], n)?;
                    corners[k] = i;
                    k += 1;
                    if k == 3 {
                        tris.push(corners);
                        k = 0;
                    }
                }
                tris
            }
            None => return Err(unreadable(ctx, path, "indices", &a)),
        },
        (_, indices) => {
            let order: Vec<u32> = match indices {
                None => (0..n as u32).collect(),
                Some(a) => match reader.read_indices() {
                    Some(it) => it.into_u32().collect(),
                    None => return Err(unreadable(ctx, path, "indices", &a)),
                },
            };
            check_indices(ctx, path, &order, n)?;
            triangulate(mode, &order)
        }
    };
    if translucent {
        ctx.warn(format!(
            "{path}: the alpha of COLOR_0 is ignored (only its RGB multiplies the base colour)"
        ));
    }
    if indices.is_empty() {
        ctx.warn(format!("{path}: has no triangles and is skipped"));
        return Ok(None);
    }
    if positions
        .iter()
        .chain(&normals)
        .chain(&colors)
        .any(|p| !p.is_finite())
        || uvs.iter().any(|uv| !uv.is_finite())
        || tangents.iter().any(|t| !t.is_finite())
    {
        return Err(ctx.error(path, "has a non-finite vertex attribute"));
    }
    Ok(Some(MeshDesc {
        positions,
        normals,
        uvs,
        indices,
        colors,
        tangents,
    }))
}

/// An error where an index is `n` or more.
fn check_indices<'a>(
    ctx: &Ctx,
    path: &str,
    indices: impl IntoIterator<Item = &'a u32>,
    n: usize,
) -> Result<(), LoadError> {
    match indices.into_iter().find(|&&i| i as usize >= n) {
        Some(i) => Err(ctx.error(path, format!("index {i} is out of range ({n} vertices)"))),
        None => Ok(()),
    }
}

/// Triangles of a primitive from its vertex order (glTF 2.0 §3.7.2.1).
pub fn triangulate(mode: Mode, order: &[u32]) -> Vec<[u32; 3]> {
    match mode {
        Mode::Triangles => order.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
        Mode::TriangleStrip => (0..order.len().saturating_sub(2))
            .map(|i| {
                let (a, b) = (order[i], order[i + 1]);
                let c = order[i + 2];
                if i % 2 == 0 {
                    [a, b, c]
                } else {
                    [b, a, c]
                }
            })
            .collect(),
        Mode::TriangleFan => (1..order.len().saturating_sub(1))
            .map(|i| [order[i], order[i + 1], order[0]])
            .collect(),
        _ => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans_keep_the_winding() {
        let order = [0, 1, 2, 3, 4];
        assert_eq!(
            triangulate(Mode::TriangleStrip, &order),
            vec![[0, 1, 2], [2, 1, 3], [2, 3, 4]]
        );
        assert_eq!(
            triangulate(Mode::TriangleFan, &order),
            vec![[1, 2, 0], [2, 3, 0], [3, 4, 0]]
        );
        assert_eq!(triangulate(Mode::Triangles, &order), vec![[0, 1, 2]]);
        assert!(triangulate(Mode::TriangleStrip, &[0, 1]).is_empty());
        assert!(triangulate(Mode::TriangleFan, &[]).is_empty());
    }
}
