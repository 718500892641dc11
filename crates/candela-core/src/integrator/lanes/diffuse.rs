//! The Lambertian lobe in lanes: [`crate::bsdf::Bsdf::sample`] of a
//! [`crate::bsdf::Lobe::Diffuse`] BSDF for eight shading points at once. Each lane runs
//! the scalar code's operations in the scalar code's order (Duff et al.'s frame, Shirley
//! and Chiu's concentric disk with the short sine and cosine polynomials, Malley's lift to
//! the hemisphere, the side checks), so a lane's sample is the scalar sample bit for bit;
//! the two branches of the disk mapping become a select.

use std::f32::consts::{FRAC_1_PI, FRAC_PI_4};

use super::simd::{F32x8, LaneIsa, Lanes32, M32x8, Vec3Lanes, Vec3x8, LANES};

/// What eight Lambertian shading points give their sampler, in memory: the shading normal
/// (the frame's z), the geometric normal, the direction towards the previous vertex and
/// the albedo, lane by lane.
#[derive(Clone, Copy, Debug)]
pub(super) struct DiffuseLanes {
    pub ns: Vec3Lanes,
    pub ng: Vec3Lanes,
    pub wo: Vec3Lanes,
    pub albedo: Vec3Lanes,
    /// Lanes whose BSDF is black from below (one-sided).
    pub one_sided: [bool; LANES],
}

/// Sampled directions of eight lanes: in the lanes of `ok`, `f`, `wi` and `pdf` are those of
/// the scalar [`crate::bsdf::BsdfSample`]; elsewhere the scalar code returned no sample
/// and the values mean nothing.
#[derive(Clone, Copy)]
pub(super) struct SampledLanes<I: LaneIsa> {
    pub f: Vec3x8<I>,
    pub wi: Vec3x8<I>,
    pub pdf: F32x8<I>,
    pub ok: M32x8<I>,
}

/// Shirley and Chiu's concentric map of `u` in [0,1)² to the unit disk, lane by lane, as
/// [`crate::sampling::sample_concentric_disk`].
#[inline(always)]
fn concentric_disk<I: LaneIsa>(ux: F32x8<I>, uy: F32x8<I>) -> (F32x8<I>, F32x8<I>) {
    let (one, two, zero) = (F32x8::splat(1.0), F32x8::splat(2.0), F32x8::splat(0.0));
    let (ox, oy) = (two * ux - one, two * uy - one);
    let x_wide = ox.abs().gt(oy.abs());
    let r = x_wide.select(ox, oy);
    let a = F32x8::splat(FRAC_PI_4) * (x_wide.select(oy, ox) / r);
    let (s, c) = sin_cos_quarter(a);
    let (dx, dy) = (r * x_wide.select(c, s), r * x_wide.select(s, c));
    let centre = ox.eq(zero).and(oy.eq(zero));
    (centre.select(zero, dx), centre.select(zero, dy))
}

/// [`crate::sampling::sin_cos_quarter`] lane by lane.
#[inline(always)]
fn sin_cos_quarter<I: LaneIsa>(a: F32x8<I>) -> (F32x8<I>, F32x8<I>) {
    let k = F32x8::<I>::splat;
    let a2 = a * a;
    let s = a
        * (k(1.0)
            + a2 * (k(-1.0 / 6.0)
                + a2 * (k(1.0 / 120.0) + a2 * (k(-1.0 / 5040.0) + a2 * k(1.0 / 362_880.0)))));
    let c = k(1.0)
        + a2 * (k(-0.5) + a2 * (k(1.0 / 24.0) + a2 * (k(-1.0 / 720.0) + a2 * k(1.0 / 40_320.0))));
    (s, c)
}

/// Duff et al.'s frame around `n` ([`crate::math::Frame::from_z`]): its first two axes.
#[inline(always)]
fn frame_from_z<I: LaneIsa>(n: &Vec3x8<I>) -> (Vec3x8<I>, Vec3x8<I>) {
    let one = F32x8::splat(1.0);
    let sign = one.copysign(n.z);
    let a = -one / (sign + n.z);
    let b = n.x * n.y * a;
    let s = Vec3x8 {
        x: one + sign * n.x * n.x * a,
        y: sign * b,
        z: -sign * n.x,
    };
    let t = Vec3x8 {
        x: b,
        y: sign + n.y * n.y * a,
        z: -n.y,
    };
    (s, t)
}

/// Cosine-weighted directions around each lane's shading normal from `u` (two numbers a
/// lane), with the Lambertian value and density: the scalar `Bsdf::sample` of a diffuse
/// lobe, lane by lane.
#[inline(always)]
pub(super) fn sample<I: LaneIsa>(d: &DiffuseLanes, u: &[Lanes32; 2]) -> SampledLanes<I> {
    let zero = F32x8::splat(0.0);
    let (ns, ng, wo) = (
        Vec3x8::load(&d.ns),
        Vec3x8::load(&d.ng),
        Vec3x8::load(&d.wo),
    );
    let cos_o = wo.dot(&ns);
    let one_sided = M32x8::from_bools(d.one_sided);
    let blind = cos_o.eq(zero).or(one_sided.and(cos_o.lt(zero)));
    let (lx, ly) = concentric_disk(F32x8::load(&u[0]), F32x8::load(&u[1]));
    let lz = (F32x8::splat(1.0) - (lx * lx + ly * ly)).max(zero).sqrt();
    let lz = cos_o.lt(zero).select(-lz, lz);
    let pdf = lz.abs().max(zero) * F32x8::splat(FRAC_1_PI);
    let f = Vec3x8::load(&d.albedo).scale(F32x8::splat(FRAC_1_PI));
    let (s, t) = frame_from_z(&ns);
    let wi = Vec3x8 {
        x: s.x * lx + t.x * ly + ns.x * lz,
        y: s.y * lx + t.y * ly + ns.y * lz,
        z: s.z * lx + t.z * ly + ns.z * lz,
    };
    // Reflection for the geometric normal exactly where it is for the shading normal.
    let geometric = (wo.dot(&ng) * wi.dot(&ng)).gt(zero);
    let shading = (cos_o * lz).gt(zero);
    let ok = blind
        .not()
        .and(pdf.gt(zero))
        .and(f.is_finite())
        .and(geometric.xor(shading).not());
    SampledLanes { f, wi, pdf, ok }
}

#[cfg(test)]
mod tests {
    use glam::{Vec2, Vec3};

    use super::super::simd::Portable;
    use super::*;
    use crate::bsdf::{Bsdf, Diffuse, Lobe};
    use crate::sampler::{IndependentSampler, Sampler};

    /// Every lane's sample equals the scalar `Bsdf::sample`'s bit for bit, and the lanes
    /// it rejects are the ones the scalar code gives no sample for, over 4096 random
    /// configurations (normals bent from the geometric one, both sides, one-sided BSDFs,
    /// and the disk's centre and edges among the numbers).
    fn lanes_sample_as_the_scalar_bsdf<I: LaneIsa>() {
        let mut rng = IndependentSampler::new(11);
        rng.start_pixel_sample(glam::UVec2::new(1, 2), 3);
        let dir =
            |rng: &mut IndependentSampler| crate::sampling::sample_uniform_sphere(rng.get_2d());
        let (mut checked, mut rejected) = (0, 0);
        for round in 0..512 {
            let mut bsdfs = Vec::new();
            let mut lanes = DiffuseLanes {
                ns: Vec3Lanes::ZERO,
                ng: Vec3Lanes::ZERO,
                wo: Vec3Lanes::ZERO,
                albedo: Vec3Lanes::ZERO,
                one_sided: [false; LANES],
            };
            let mut u_lanes = [[0.0; LANES]; 2];
            for i in 0..LANES {
                let ng = dir(&mut rng);
                let ns = (ng + 0.4 * dir(&mut rng)).normalize();
                let wo = dir(&mut rng);
                let albedo = Vec3::new(rng.get_1d(), rng.get_1d(), 0.5);
                let mut bsdf = Bsdf::new(ns, ng, Lobe::Diffuse(Diffuse { albedo }));
                bsdf.one_sided = (round + i) % 3 == 0;
                lanes.one_sided[i] = bsdf.one_sided;
                let u = match (round + i) % 16 {
                    0 => Vec2::splat(0.5),
                    1 => Vec2::new(0.0, rng.get_1d()),
                    _ => rng.get_2d(),
                };
                lanes.ns.set_lane(i, ns);
                lanes.ng.set_lane(i, ng);
                lanes.wo.set_lane(i, wo);
                lanes.albedo.set_lane(i, albedo);
                let [ux, uy] = &mut u_lanes;
                (ux[i], uy[i]) = (u.x, u.y);
                bsdfs.push((bsdf, wo, u));
            }
            let got = sample::<I>(&lanes, &u_lanes);
            let (ok, wi, f, pdf) = (
                got.ok.bits(),
                got.wi.store(),
                got.f.store(),
                got.pdf.store(),
            );
            for (i, (bsdf, wo, u)) in bsdfs.iter().enumerate() {
                match bsdf.sample(*wo, 0.5, *u) {
                    Some(s) => {
                        assert!(ok & (1 << i) != 0, "round {round} lane {i}: lanes rejected");
                        assert_eq!(
                            wi.lane(i).to_array().map(f32::to_bits),
                            s.wi.to_array().map(f32::to_bits)
                        );
                        assert_eq!(f.lane(i), s.f);
                        assert_eq!(pdf[i].to_bits(), s.pdf.to_bits());
                        checked += 1;
                    }
                    None => {
                        assert!(
                            ok & (1 << i) == 0,
                            "round {round} lane {i}: scalar rejected"
                        );
                        rejected += 1;
                    }
                }
            }
        }
        // Both outcomes occur often enough for the comparison to mean something.
        assert!(
            checked > 1000 && rejected > 100,
            "{checked} sampled, {rejected} rejected"
        );
    }

    #[test]
    fn portable_lanes_sample_as_the_scalar_bsdf() {
        lanes_sample_as_the_scalar_bsdf::<Portable>();
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx2_lanes_sample_as_the_scalar_bsdf() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            eprintln!("NOTE: no AVX2 on this CPU: the AVX2 lanes are not tested");
            return;
        }
        // SAFETY: the CPU has AVX2 (checked above).
        #[target_feature(enable = "avx,avx2")]
        unsafe fn run() {
            lanes_sample_as_the_scalar_bsdf::<super::super::simd::Avx2>();
        }
        unsafe { run() }
    }
}
