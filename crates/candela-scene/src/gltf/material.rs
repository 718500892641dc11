//! glTF materials as [`BsdfDesc`]s.
//!
//! - Metallic-roughness: base colour = factor × texture (sRGB-decoded); metallic and
//!   roughness = factors × the B and G channels of their texture (linear).
//! - Normal texture: linear, its `scale` baked into the image's x and y
//!   ((2c − 1)·scale, clamped to [−1, 1] where scale > 1).
//! - Emission: `emissiveFactor` × KHR_materials_emissive_strength × the emissive texture
//!   (sRGB-decoded), read as radiance in W·sr⁻¹·m⁻² (linear Rec.709): a textured area
//!   light.
//! - Occlusion textures are ignored: a path tracer computes occlusion itself.
//! - Alpha: `MASK` and `BLEND` wrap the BSDF in [`BsdfDesc::Alpha`] with α = base colour
//!   alpha factor × texture alpha.
//! - KHR_materials_transmission makes a rough dielectric of index KHR_materials_ior
//!   (default 1.5) and α = roughness², its transmission tinted by the base colour (factor
//!   × texture, times vertex colours). A partial transmission t (the factor × the red
//!   channel of its texture) mixes it with the metallic-roughness BSDF by t·(1 − metallic)
//!   ([`BsdfDesc::Mix`]): the extension's model for a dielectric. Where metallic comes
//!   from a texture, t is not scaled by it.
//! - `doubleSided` wraps the BSDF in [`BsdfDesc::TwoSided`]; Candela's BSDFs reflect on
//!   both sides either way (a path tracer does not cull back faces).
//! - Samplers: wrap S (T must agree, else a warning) as the texture's wrap mode; lookups
//!   are always bilinear, so filter modes are ignored with a warning where they ask for
//!   nearest.

use std::collections::HashMap;
use std::sync::Arc;

use candela_core::alpha::AlphaMode;
use candela_core::desc::{
    AlphaDesc, BsdfDesc, ImageDesc, ImageTextureDesc, MaterialDesc, MicrofacetDesc, TextureDesc,
    WrapMode,
};
use glam::{Affine2, Mat2, Vec2, Vec3};

use super::image::{self, Use};
use super::Ctx;
use crate::LoadError;

/// What a shape needs of its material.
#[derive(Clone, Debug)]
pub(crate) struct MaterialInfo {
    pub name: String,
    pub emission: Option<Vec3>,
    /// The emissive texture, multiplying `emission`.
    pub emission_texture: Option<TextureDesc>,
    /// The TEXCOORD set the material's textures read.
    pub tex_coord: u32,
    pub has_normal_map: bool,
}

/// Materials and decoded images converted so far.
#[derive(Default)]
pub(crate) struct Materials {
    infos: HashMap<Option<usize>, MaterialInfo>,
    descs: Vec<MaterialDesc>,
    images: HashMap<(usize, Use), Arc<ImageDesc>>,
}

impl Materials {
    pub fn into_descs(self) -> Vec<MaterialDesc> {
        self.descs
    }

    /// The material (converted on first use); `index() == None` is glTF's default.
    pub fn get(&mut self, ctx: &mut Ctx, m: &gltf::Material) -> Result<MaterialInfo, LoadError> {
        if let Some(info) = self.infos.get(&m.index()) {
            return Ok(info.clone());
        }
        let (desc, info) = self.convert(ctx, m)?;
        self.descs.push(desc);
        self.infos.insert(m.index(), info.clone());
        Ok(info)
    }

    fn convert(
        &mut self,
        ctx: &mut Ctx,
        m: &gltf::Material,
    ) -> Result<(MaterialDesc, MaterialInfo), LoadError> {
        let path = match m.index() {
            Some(i) => format!("materials[{i}]"),
            None => "default material".to_string(),
        };
        let name = match m.index() {
            Some(i) => format!("{}gltf{i}:{}", ctx.prefix, m.name().unwrap_or("")),
            None => format!("{}gltf:default", ctx.prefix),
        };
        let pbr = m.pbr_metallic_roughness();
        let tex_coord = pbr
            .base_color_texture()
            .map(|t| tex_coord(&t))
            .or_else(|| pbr.metallic_roughness_texture().map(|t| tex_coord(&t)))
            .or_else(|| m.emissive_texture().map(|t| tex_coord(&t)))
            .unwrap_or(0);
        let [r, g, b, a] = pbr.base_color_factor();
        let base_factor = Vec3::new(r, g, b);
        let base_color = match pbr.base_color_texture() {
            Some(t) => self.texture(ctx, &path, &t, Use::Color, base_factor, None, tex_coord)?,
            None => TextureDesc::Constant(base_factor),
        };
        let (metallic, roughness) = match pbr.metallic_roughness_texture() {
            Some(t) => (
                self.texture(
                    ctx,
                    &path,
                    &t,
                    Use::Data,
                    Vec3::splat(pbr.metallic_factor()),
                    Some(2),
                    tex_coord,
                )?,
                self.texture(
                    ctx,
                    &path,
                    &t,
                    Use::Data,
                    Vec3::splat(pbr.roughness_factor()),
                    Some(1),
                    tex_coord,
                )?,
            ),
            None => (
                TextureDesc::Constant(Vec3::splat(pbr.metallic_factor())),
                TextureDesc::Constant(Vec3::splat(pbr.roughness_factor())),
            ),
        };
        let transmission = m.transmission().map_or(0.0, |t| t.transmission_factor());
        let transmission_texture = m.transmission().and_then(|t| t.transmission_texture());
        let ior = m.ior().unwrap_or(1.5);
        let glass = || {
            let alpha = pbr.roughness_factor().clamp(0.0, 1.0).powi(2);
            BsdfDesc::Dielectric {
                eta: ior,
                alpha_u: alpha,
                alpha_v: alpha,
                distribution: MicrofacetDesc::Ggx,
                thin: false,
                tint: base_color.clone(),
            }
        };
        let opaque = || BsdfDesc::MetalRough {
            base_color: base_color.clone(),
            metallic: metallic.clone(),
            roughness: roughness.clone(),
        };
        if transmission <= 0.0 && (ior - 1.5).abs() > 1e-6 {
            ctx.warn(format!(
                "{path}: ior {ior} only affects transmission; the metallic-roughness model \
                 keeps F0 = 0.04"
            ));
        }
        let mut bsdf = if transmission <= 0.0 {
            opaque()
        } else if transmission >= 1.0 && transmission_texture.is_none() {
            glass()
        } else {
            // The extension's dielectric is mix(diffuse, transmission, t) under the same
            // Fresnel-weighted specular layer. Mixing the whole metallic-roughness BSDF
            // with the glass by t gives exactly that for a dielectric, up to Schlick's F
            // against the glass's exact one. Metals do not transmit, so t is scaled by
            // 1 − metallic (exact at metallic 0 and 1) where metallic is a factor alone;
            // a metallic texture is not looked up for it.
            let opacity = match pbr.metallic_roughness_texture() {
                Some(_) => 1.0,
                None => 1.0 - pbr.metallic_factor().clamp(0.0, 1.0),
            };
            let w = transmission.min(1.0) * opacity;
            let weight = match &transmission_texture {
                Some(t) => {
                    self.texture(ctx, &path, t, Use::Data, Vec3::splat(w), Some(0), tex_coord)?
                }
                None => TextureDesc::Constant(Vec3::splat(w)),
            };
            BsdfDesc::Mix {
                weight,
                a: Box::new(opaque()),
                b: Box::new(glass()),
            }
        };
        let normal = m.normal_texture();
        if let Some(n) = &normal {
            let scale = n.scale();
            // The `gltf` crate reads KHR_texture_transform only on plain texture slots.
            let transform = n
                .extension_value("KHR_texture_transform")
                .map(json_texture_transform);
            let set = transform.and_then(|t| t.3).unwrap_or(n.tex_coord());
            let map = self.image_texture(
                ctx,
                &path,
                &n.texture(),
                Use::Normal(scale.to_bits()),
                Vec3::ONE,
                None,
                set,
                tex_coord,
                transform.map(|(o, r, s, _)| (o, r, s)),
            )?;
            bsdf = BsdfDesc::NormalMap {
                map,
                inner: Box::new(bsdf),
            };
        }
        if m.occlusion_texture().is_some() {
            ctx.warn(format!(
                "{path}: occlusion texture ignored (path tracing computes occlusion)"
            ));
        }
        match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => {}
            mode => {
                let mode = match mode {
                    gltf::material::AlphaMode::Mask => AlphaMode::Mask {
                        cutoff: m.alpha_cutoff().unwrap_or(0.5),
                    },
                    _ => AlphaMode::Blend,
                };
                let texture = match pbr.base_color_texture() {
                    Some(t) => Some(self.texture(
                        ctx,
                        &path,
                        &t,
                        Use::Alpha,
                        Vec3::ONE,
                        None,
                        tex_coord,
                    )?),
                    None => None,
                };
                bsdf = BsdfDesc::Alpha {
                    alpha: AlphaDesc {
                        mode,
                        factor: a,
                        texture,
                    },
                    inner: Box::new(bsdf),
                };
            }
        }
        if m.double_sided() {
            bsdf = BsdfDesc::TwoSided(Box::new(bsdf));
        }
        let strength = m.emissive_strength().unwrap_or(1.0);
        let emission = Vec3::from(m.emissive_factor()) * strength;
        let emission_texture = match m.emissive_texture() {
            Some(t) if emission != Vec3::ZERO => {
                Some(self.texture(ctx, &path, &t, Use::Color, Vec3::ONE, None, tex_coord)?)
            }
            _ => None,
        };
        let has_normal_map = normal.is_some();
        let info = MaterialInfo {
            name: name.clone(),
            emission: (emission != Vec3::ZERO).then_some(emission),
            emission_texture,
            tex_coord,
            has_normal_map,
        };
        Ok((
            MaterialDesc {
                name,
                bsdf,
                span: ctx.span(),
            },
            info,
        ))
    }

    /// A texture slot: `info`'s image as `use_`, times `scale`, through `channel`.
    #[allow(clippy::too_many_arguments)]
    fn texture(
        &mut self,
        ctx: &mut Ctx,
        path: &str,
        info: &gltf::texture::Info,
        use_: Use,
        scale: Vec3,
        channel: Option<u8>,
        mesh_tex_coord: u32,
    ) -> Result<TextureDesc, LoadError> {
        let transform = info
            .texture_transform()
            .map(|t| (t.offset(), t.rotation(), t.scale()));
        self.image_texture(
            ctx,
            path,
            &info.texture(),
            use_,
            scale,
            channel,
            tex_coord(info),
            mesh_tex_coord,
            transform,
        )
    }

    #[allow(clippy::too_many_arguments)]
    fn image_texture(
        &mut self,
        ctx: &mut Ctx,
        path: &str,
        texture: &gltf::Texture,
        use_: Use,
        scale: Vec3,
        channel: Option<u8>,
        tex_coord: u32,
        mesh_tex_coord: u32,
        transform: Option<([f32; 2], f32, [f32; 2])>,
    ) -> Result<TextureDesc, LoadError> {
        if tex_coord != mesh_tex_coord {
            ctx.warn(format!(
                "{path}: a texture reads TEXCOORD_{tex_coord} but the material's base colour \
                 reads TEXCOORD_{mesh_tex_coord}; all its textures use the latter"
            ));
        }
        let image = self.image(ctx, path, texture, use_)?;
        let sampler = texture.sampler();
        let wrap = wrap_mode(sampler.wrap_s());
        if wrap != wrap_mode(sampler.wrap_t()) {
            ctx.warn(format!(
                "{path}: sampler wraps S and T differently; S's mode is used for both"
            ));
        }
        if sampler.mag_filter() == Some(gltf::texture::MagFilter::Nearest) {
            ctx.warn(format!(
                "{path}: nearest filtering is not supported; textures are bilinear"
            ));
        }
        Ok(TextureDesc::Image(ImageTextureDesc {
            image,
            wrap,
            uv_transform: transform.map_or(Affine2::IDENTITY, |(o, r, s)| uv_transform(o, r, s)),
            scale,
            channel,
        }))
    }

    /// A decoded image, cached per use.
    fn image(
        &mut self,
        ctx: &mut Ctx,
        path: &str,
        texture: &gltf::Texture,
        use_: Use,
    ) -> Result<Arc<ImageDesc>, LoadError> {
        let source = texture.source();
        let key = (source.index(), use_);
        if let Some(img) = self.images.get(&key) {
            return Ok(img.clone());
        }
        let img = image::decode(ctx, path, texture, use_)?;
        let img = Arc::new(img);
        self.images.insert(key, img.clone());
        Ok(img)
    }
}

/// KHR_texture_transform's offset, rotation, scale and texCoord from its JSON, with the
/// extension's defaults.
fn json_texture_transform(v: &gltf::json::Value) -> ([f32; 2], f32, [f32; 2], Option<u32>) {
    let pair = |key: &str, default: [f32; 2]| {
        v.get(key)
            .and_then(|a| a.as_array())
            .filter(|a| a.len() == 2)
            .and_then(|a| Some([a[0].as_f64()? as f32, a[1].as_f64()? as f32]))
            .unwrap_or(default)
    };
    let rotation = v.get("rotation").and_then(|r| r.as_f64()).unwrap_or(0.0) as f32;
    let set = v.get("texCoord").and_then(|t| t.as_u64()).map(|t| t as u32);
    (
        pair("offset", [0.0; 2]),
        rotation,
        pair("scale", [1.0; 2]),
        set,
    )
}

/// The TEXCOORD set a texture slot reads (KHR_texture_transform may override it).
fn tex_coord(info: &gltf::texture::Info) -> u32 {
    info.texture_transform()
        .and_then(|t| t.tex_coord())
        .unwrap_or(info.tex_coord())
}

fn wrap_mode(w: gltf::texture::WrappingMode) -> WrapMode {
    match w {
        gltf::texture::WrappingMode::ClampToEdge => WrapMode::Clamp,
        gltf::texture::WrappingMode::MirroredRepeat => WrapMode::Mirror,
        gltf::texture::WrappingMode::Repeat => WrapMode::Repeat,
    }
}

/// KHR_texture_transform's T·R·S (offset, rotation, scale) moved into Candela's uv
/// convention: with F(u, v) = (u, 1 − v) the flip between glTF's and Candela's v, the
/// lookup transform is F ∘ (T·R·S) ∘ F.
pub fn uv_transform(offset: [f32; 2], rotation: f32, scale: [f32; 2]) -> Affine2 {
    let (s, c) = rotation.sin_cos();
    // The extension's rotation matrix, rows (c, s) and (−s, c).
    let r = Mat2::from_cols(Vec2::new(c, -s), Vec2::new(s, c));
    let trs = Affine2::from_mat2_translation(
        r * Mat2::from_diagonal(Vec2::from(scale)),
        Vec2::from(offset),
    );
    let flip = Affine2::from_mat2_translation(
        Mat2::from_diagonal(Vec2::new(1.0, -1.0)),
        Vec2::new(0.0, 1.0),
    );
    flip * trs * flip
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_transform_acts_in_gltf_uvs() {
        // A glTF uv (u, v) is Candela's (u, 1 − v); transform in glTF terms, flip back.
        let (o, r, s) = ([0.25, 0.5], 0.3f32, [2.0, 3.0]);
        let t = uv_transform(o, r, s);
        let g = Vec2::new(0.1, 0.2);
        let (sn, cs) = r.sin_cos();
        let (su, sv) = (g.x * s[0], g.y * s[1]);
        let expected_g = Vec2::new(cs * su + sn * sv + o[0], -sn * su + cs * sv + o[1]);
        let got = t.transform_point2(Vec2::new(g.x, 1.0 - g.y));
        assert!(
            (got - Vec2::new(expected_g.x, 1.0 - expected_g.y)).length() < 1e-6,
            "{got}"
        );
        assert_eq!(uv_transform([0.0; 2], 0.0, [1.0; 2]), Affine2::IDENTITY);
    }

    #[test]
    fn texture_transform_json_has_the_extension_defaults() {
        let v = serde_json::json!({"offset": [0.5, 0.25], "texCoord": 1});
        assert_eq!(
            json_texture_transform(&v),
            ([0.5, 0.25], 0.0, [1.0, 1.0], Some(1))
        );
        let v = serde_json::json!({"rotation": 0.5, "scale": [2, 3], "offset": "bad"});
        assert_eq!(
            json_texture_transform(&v),
            ([0.0, 0.0], 0.5, [2.0, 3.0], None)
        );
    }
}
