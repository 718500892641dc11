//! A bare mesh file (`.obj`, `.ply`) rendered as a scene: the mesh under the automatic
//! camera and light of a glTF file that has neither (a three-quarter view framing the
//! mesh, a uniform white sky), at Candela's default render settings.
//!
//! Materials: a PLY mesh is diffuse of its vertex colours, or grey (albedo 0.5, the TOML
//! default) without them, as are OBJ faces without a material. An OBJ's `mtllib` materials become diffuse materials of colour `Kd`
//! (default 0.5) or texture `map_Kd` (sRGB; path relative to the OBJ file, as most
//! exporters write it, `\` read as `/`), emitting `Ke` where it is not black. The Phong
//! terms (`Ks`, `Ns`, `illum`), transparency (`d`, `Tr`) and the other maps have no
//! faithful counterpart and are named in a warning; a missing MTL file is a warning too,
//! its faces grey.

use std::path::Path;
use std::sync::Arc;

use candela_core::desc::{
    BsdfDesc, GeometryDesc, ImageTextureDesc, MaterialDesc, MeshDesc, SceneDesc, ShapeDesc, Span,
    TextureDesc,
};
use glam::{Mat4, Vec3};

use crate::gltf::{camera::framing_camera, light_if_unlit};
use crate::image_texture::{load_image, Encoding};
use crate::{obj, ply, LoadError, LoadedScene, MeshError};

/// Albedo of the grey material (the TOML default).
const GREY: f32 = 0.5;

/// The name of the grey material of faces that name none (in brackets, so that it cannot
/// be an MTL material's: MTL names have no spaces).
const NO_MATERIAL: &str = "(no material)";

/// Loads an `.obj` or `.ply` file as a scene (see the module docs).
pub(crate) fn load_mesh_scene(path: &Path, ext: &str) -> Result<LoadedScene, LoadError> {
    let file = path.display().to_string();
    let span = Span::new(file.clone(), 0, 0);
    let mesh_error = |e: MeshError| {
        let line = e.line.map_or(0, |l| l as u32);
        LoadError::new(Span::new(file.clone(), line, 0), e.message)
    };
    let mut desc = SceneDesc::default();
    let mut warnings = Vec::new();
    let grey = || MaterialDesc {
        name: NO_MATERIAL.into(),
        bsdf: diffuse(TextureDesc::Constant(Vec3::splat(GREY))),
        span: span.clone(),
    };
    if ext == "ply" {
        let mesh = ply::load_ply(path).map_err(mesh_error)?;
        // Vertex colours multiply the albedo: they are the colour.
        let albedo = if mesh.colors.is_empty() { GREY } else { 1.0 };
        desc.materials.push(MaterialDesc {
            bsdf: diffuse(TextureDesc::Constant(Vec3::splat(albedo))),
            ..grey()
        });
        desc.shapes.push(shape(mesh, NO_MATERIAL, None, &span));
    } else {
        let parts = obj::load_obj_parts(path).map_err(mesh_error)?;
        if let Some(e) = &parts.mtl_error {
            warnings.push(format!(
                "{file}: materials not read ({e}): its faces are grey"
            ));
        }
        let dir = path.parent().unwrap_or(Path::new("."));
        let mut ignored: Vec<&str> = Vec::new();
        for (id, mesh) in parts.meshes {
            let Some(m) = id.and_then(|i| parts.materials.get(i)) else {
                if !desc.materials.iter().any(|m| m.name == NO_MATERIAL) {
                    desc.materials.push(grey());
                }
                desc.shapes.push(shape(mesh, NO_MATERIAL, None, &span));
                continue;
            };
            let albedo = match &m.diffuse_texture {
                Some(t) => {
                    // Exporters on Windows write `textures\wood.png`.
                    let image = load_image(&dir.join(t.replace('\\', "/")), Encoding::Srgb)
                        .map_err(|e| LoadError::new(span.clone(), e))?;
                    TextureDesc::Image(ImageTextureDesc::new(Arc::new(image)))
                }
                None => TextureDesc::Constant(m.diffuse.map_or(Vec3::splat(GREY), Vec3::from)),
            };
            let name = m.name.clone();
            if !desc.materials.iter().any(|d| d.name == name) {
                desc.materials.push(MaterialDesc {
                    name: name.clone(),
                    bsdf: diffuse(albedo),
                    span: span.clone(),
                });
            }
            let emission = m.emissive.map(Vec3::from).filter(|e| *e != Vec3::ZERO);
            desc.shapes.push(shape(mesh, &name, emission, &span));
            ignored.extend(ignored_terms(m));
        }
        ignored.sort_unstable();
        ignored.dedup();
        if !ignored.is_empty() {
            warnings.push(format!(
                "{file}: materials: {} ignored (each becomes a diffuse of its Kd or map_Kd)",
                ignored.join(", ")
            ));
        }
    }
    desc.camera = framing_camera(&desc.shapes, desc.camera.fov_y_deg);
    light_if_unlit(&mut desc, path, &mut warnings);
    Ok(LoadedScene { desc, warnings })
}

fn diffuse(albedo: TextureDesc) -> BsdfDesc {
    BsdfDesc::Diffuse { albedo }
}

fn shape(mesh: MeshDesc, material: &str, emission: Option<Vec3>, span: &Span) -> ShapeDesc {
    ShapeDesc {
        geometry: GeometryDesc::Mesh(Arc::new(mesh)),
        material: material.into(),
        emission,
        emission_texture: None,
        transform: Mat4::IDENTITY,
        flip_normals: false,
        span: span.clone(),
    }
}

/// The MTL statements of `m` that the diffuse material leaves out.
fn ignored_terms(m: &tobj::Material) -> Vec<&'static str> {
    let nonzero = |c: Option<[f32; 3]>| c.is_some_and(|c| c != [0.0; 3]);
    let mut out = Vec::new();
    if nonzero(m.specular) || m.specular_texture.is_some() {
        out.push("Ks");
    }
    if m.dissolve.is_some_and(|d| d < 1.0) || m.dissolve_texture.is_some() {
        out.push("d");
    }
    if m.normal_texture.is_some() {
        out.push("bump/norm");
    }
    if m.illumination_model.is_some_and(|i| i > 2) {
        out.push("illum > 2");
    }
    out
}
