//! Rays, boxes and the two primitive intersection tests: a watertight ray–triangle test
//! and a ray–sphere test.

use glam::Vec3;

#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub o: Vec3,
    pub d: Vec3,
}

impl Ray {
    pub fn new(o: Vec3, d: Vec3) -> Ray {
        Ray { o, d }
    }

    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}

/// An axis-aligned box. The empty box has `min = +∞`, `max = -∞`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Aabb::EMPTY
    }
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::INFINITY,
        max: Vec3::NEG_INFINITY,
    };

    pub fn from_points(points: &[Vec3]) -> Aabb {
        points.iter().fold(Aabb::EMPTY, |b, &p| b.grow(p))
    }

    pub fn grow(self, p: Vec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    pub fn extent(&self) -> Vec3 {
        if self.is_empty() {
            Vec3::ZERO
        } else {
            self.max - self.min
        }
    }

    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    pub fn surface_area(&self) -> f32 {
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// Slab test with a precomputed reciprocal direction; returns the entry distance if the
    /// ray meets the box within (0, t_max). Robust to ±∞ reciprocals (Williams et al. 2005),
    /// with the far distance scaled up by 1 + 2γ₃ so that rounding cannot miss a box the
    /// ray grazes (pbrt-v4 §6.8.2).
    #[inline]
    pub fn hit(&self, o: Vec3, inv_d: Vec3, t_max: f32) -> Option<f32> {
        // Near and far planes chosen by the direction's sign (not by min/max of the two
        // distances), so an empty box (min > max) is missed.
        let pick = |lo: f32, hi: f32, inv: f32| if inv >= 0.0 { (lo, hi) } else { (hi, lo) };
        let (nx, fx) = pick(self.min.x, self.max.x, inv_d.x);
        let (ny, fy) = pick(self.min.y, self.max.y, inv_d.y);
        let (nz, fz) = pick(self.min.z, self.max.z, inv_d.z);
        let near = (Vec3::new(nx, ny, nz) - o) * inv_d;
        let far = (Vec3::new(fx, fy, fz) - o) * inv_d * (1.0 + 2.0 * gamma(3));
        // A ray parallel to a slab and starting on one of its planes gives 0·∞ = NaN
        // there. `f32::max` and `f32::min` drop a NaN operand, so that axis counts as
        // inside its slab (conservative), and the other axes still decide; glam's
        // `max_element`/`min_element` may instead carry the NaN through and accept a box
        // whose other slab the ray misses.
        let t_near = near.x.max(near.y).max(near.z).max(0.0);
        let t_far = far.x.min(far.y).min(far.z).min(t_max);
        (t_near <= t_far).then_some(t_near)
    }
}

/// γₙ = nε/(1 − nε), the bound on relative error after n floating-point operations.
pub const fn gamma(n: i32) -> f32 {
    let e = f32::EPSILON * 0.5;
    (n as f32 * e) / (1.0 - n as f32 * e)
}

/// Where a ray meets a triangle: distance and barycentrics of vertices 1 and 2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    pub b1: f32,
    pub b2: f32,
}

/// Per-ray constants of the watertight triangle test.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    pub(crate) o: Vec3,
    /// The axis along which the direction is largest is `kz`; `kx`, `ky` the others, in
    /// the order that keeps the winding. Each is below 3 (the vector tests index by
    /// them unchecked).
    pub(crate) kx: usize,
    pub(crate) ky: usize,
    pub(crate) kz: usize,
    /// (d[kx]/d[kz], d[ky]/d[kz], 1/d[kz]).
    pub(crate) shear: Vec3,
    /// (o[kx], o[ky], o[kz]): what the vector tests splat, picked once per ray.
    pub(crate) o_k: Vec3,
}

/// `[kx, ky]` by `kz` (row) and by whether `d[kz] < 0` (column): the two other axes in
/// cyclic order, swapped for a negative `d[kz]` to keep the winding. A static table, so
/// that it is not rebuilt on the stack at every ray.
static AXES: [[[usize; 2]; 2]; 3] = [[[1, 2], [2, 1]], [[2, 0], [0, 2]], [[0, 1], [1, 0]]];

impl WatertightRay {
    #[inline]
    pub fn new(ray: &Ray) -> WatertightRay {
        WatertightRay::with_sz(ray, |_, dz| 1.0 / dz)
    }

    /// [`WatertightRay::new`] with `1/d[kz]` taken from `inv_d = ray.d.recip()`, which
    /// traversal has computed anyway: the same division of the same value, so the same
    /// bits, without a second one.
    #[inline(always)]
    pub(crate) fn from_recip(ray: &Ray, inv_d: Vec3) -> WatertightRay {
        let inv = inv_d.to_array();
        // SAFETY: `kz` is below 3.
        WatertightRay::with_sz(ray, |kz, _| unsafe { *inv.get_unchecked(kz) })
    }

    /// `sz(kz, d[kz])` gives `1/d[kz]`.
    #[inline(always)]
    fn with_sz(ray: &Ray, sz: impl FnOnce(usize, f32) -> f32) -> WatertightRay {
        let d = ray.d.to_array();
        // `d.abs().max_position()` (the first of equals), and the other two axes from
        // `AXES`: selects and a table lookup, no branches. Random directions made the
        // branches mispredict about once a ray (callgrind's branch model on the Cornell
        // render: 0.8 of 3.9 mispredictions a closest-hit query, 0.5 of 1.5 a shadow
        // ray).
        let a = ray.d.abs();
        let y_wins = a.y > a.x;
        let max = if y_wins { a.y } else { a.x };
        let kz = if a.z > max { 2 } else { y_wins as usize };
        let o = ray.o.to_array();
        // SAFETY: called only with `kz` (0, 1 or 2) and entries of `AXES` (the same).
        let at = |v: &[f32; 3], k: usize| unsafe { *v.get_unchecked(k) };
        let dz = at(&d, kz);
        let [kx, ky] = AXES[kz][(dz < 0.0) as usize];
        let sz = sz(kz, dz);
        WatertightRay {
            o: ray.o,
            kx,
            ky,
            kz,
            shear: Vec3::new(at(&d, kx) * sz, at(&d, ky) * sz, sz),
            o_k: Vec3::new(at(&o, kx), at(&o, ky), at(&o, kz)),
        }
    }

    /// Woop, Benthin and Wald 2013, "Watertight Ray/Triangle Intersection": a ray never
    /// slips between two triangles that share an edge. Returns a hit with 0 < t < t_max.
    ///
    /// The test as the paper has it (vertices moved to the ray's frame, 2D edge functions
    /// never fused), with two changes. An edge function that rounds to exactly zero
    /// counts as inside, without the paper's double-precision retry: the two triangles
    /// that share an edge compute its function from the same two transformed vertices
    /// with the operands swapped (products commute, and `x − y = −(y − x)` exactly), so
    /// where one sees a nonzero value the other sees its negation and exactly one of them
    /// is hit, and where both see zero both are: a ray may meet either or both, never
    /// neither (watertight without the retry, which cost every vector lane three
    /// comparisons and a scalar fallback). And the distance test written with fewer
    /// operations and the same outcome: the determinant's sign folded into the scaled
    /// distance (sign-bit flips, exact), then one comparison with zero and one with
    /// `t_max · |det|`, where the paper picks one of two pairs by the sign. The block
    /// kernels ([`crate::accel`]) perform the same operations in the same order, so every
    /// lane gives these bits.
    #[inline]
    pub fn intersect(&self, p0: Vec3, p1: Vec3, p2: Vec3, t_max: f32) -> Option<TriangleHit> {
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        let a = p0 - self.o;
        let b = p1 - self.o;
        let c = p2 - self.o;
        let (sx, sy, sz) = (self.shear.x, self.shear.y, self.shear.z);
        let ax = a[kx] - sx * a[kz];
        let ay = a[ky] - sy * a[kz];
        let bx = b[kx] - sx * b[kz];
        let by = b[ky] - sy * b[kz];
        let cx = c[kx] - sx * c[kz];
        let cy = c[ky] - sy * c[kz];
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        // Outside where some edge function is negative and another positive: a zero one
        // (the ray through an edge or vertex, or a value that rounds to zero) is inside.
        if u.min(v).min(w) < 0.0 && u.max(v).max(w) > 0.0 {
            return None;
        }
        let det = u + v + w;
        let az = sz * a[kz];
        let bz = sz * b[kz];
        let cz = sz * c[kz];
        let t_scaled = u * az + v * bz + w * cz;
        // The sign of `det` moved onto the distance (`t_signed / |det|` is the distance):
        // `t_signed <= 0` is the paper's `t_scaled <= 0` for a positive `det` and
        // `t_scaled >= 0` for a negative one, `t_signed > t_max · |det|` its
        // `t_scaled > t_max · det` and `t_scaled < t_max · det` (negation is exact), so
        // the outcome is the paper's; a zero `det` leaves no distance below
        // `t_max · 0 = 0` (where `t_max` is infinite, `t_max · 0` is NaN and `t` the
        // infinity or NaN that the check after the division rejects).
        let sign = det.to_bits() & 0x8000_0000;
        let det_abs = f32::from_bits(det.to_bits() ^ sign);
        let t_signed = f32::from_bits(t_scaled.to_bits() ^ sign);
        // Reject hits behind the origin or beyond t_max without dividing (and every
        // distance where `det` is zero, or NaN: the negated comparison is true for NaN).
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(t_signed > 0.0) || t_signed > t_max * det_abs {
            return None;
        }
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        Some(TriangleHit {
            t,
            b1: v * inv_det,
            b2: w * inv_det,
        })
    }
}

/// The nearest intersection with 0 < t < t_max of a ray with a sphere. Solves the
/// quadratic in the numerically stable form of pbrt-v4 §6.2.2 (discriminant from the
/// distance to the closest point, Hearn–Baker).
pub fn intersect_sphere(ray: &Ray, center: Vec3, radius: f32, t_max: f32) -> Option<f32> {
    let o = ray.o - center;
    let a = ray.d.length_squared();
    let b = 2.0 * ray.d.dot(o);
    let c = o.length_squared() - radius * radius;
    let v = o - (b / (2.0 * a)) * ray.d;
    let len = v.length();
    let discrim = 4.0 * a * (radius + len) * (radius - len);
    if discrim < 0.0 {
        return None;
    }
    let root = discrim.sqrt();
    let q = if b < 0.0 {
        -0.5 * (b - root)
    } else {
        -0.5 * (b + root)
    };
    let (mut t0, mut t1) = (q / a, c / q);
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    // Roots within the relative error of the computation of the origin's distance are
    // self-hits of a ray leaving the surface.
    let eps = 1e-4 * radius;
    if t0 > eps && t0 < t_max {
        Some(t0)
    } else if t1 > eps && t1 < t_max {
        Some(t1)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> (Vec3, Vec3, Vec3) {
        (
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        )
    }

    #[test]
    fn triangle_hit_and_barycentrics() {
        let (a, b, c) = tri();
        let ray = Ray::new(Vec3::new(0.0, 0.0, 2.0), Vec3::new(0.0, 0.0, -1.0));
        let h = WatertightRay::new(&ray)
            .intersect(a, b, c, f32::INFINITY)
            .unwrap();
        assert!((h.t - 2.0).abs() < 1e-6);
        let p = a * (1.0 - h.b1 - h.b2) + b * h.b1 + c * h.b2;
        assert!(p.length() < 1e-6);
        // Beyond t_max, behind the origin, and outside the triangle: no hit.
        assert!(WatertightRay::new(&ray).intersect(a, b, c, 1.5).is_none());
        let back = Ray::new(Vec3::new(0.0, 0.0, -2.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(WatertightRay::new(&back)
            .intersect(a, b, c, f32::INFINITY)
            .is_none());
        let off = Ray::new(Vec3::new(2.0, 0.0, 2.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(WatertightRay::new(&off)
            .intersect(a, b, c, f32::INFINITY)
            .is_none());
    }

    #[test]
    fn shared_edge_is_watertight() {
        // Two triangles sharing the edge x = 0; rays aimed exactly at the edge hit one.
        let (p0, p1, p2, p3) = (
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
        );
        for i in 0..1000 {
            let y = -0.99 + 1.98 * i as f32 / 1000.0;
            let ray = Ray::new(
                Vec3::new(0.0, y, 1.0),
                Vec3::new(1e-9 * i as f32, 0.0, -1.0).normalize(),
            );
            let w = WatertightRay::new(&ray);
            let hits = w.intersect(p0, p1, p2, f32::INFINITY).is_some() as u32
                + w.intersect(p1, p0, p3, f32::INFINITY).is_some() as u32;
            assert!(hits >= 1, "ray {i} slipped through the shared edge");
        }
    }

    #[test]
    fn sphere_hits_near_and_far_root() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(
            (intersect_sphere(&ray, Vec3::ZERO, 1.0, f32::INFINITY).unwrap() - 4.0).abs() < 1e-5
        );
        let inside = Ray::new(Vec3::ZERO, Vec3::X);
        assert!(
            (intersect_sphere(&inside, Vec3::ZERO, 2.0, f32::INFINITY).unwrap() - 2.0).abs() < 1e-5
        );
        let miss = Ray::new(Vec3::new(0.0, 2.0, 5.0), Vec3::new(0.0, 0.0, -1.0));
        assert!(intersect_sphere(&miss, Vec3::ZERO, 1.0, f32::INFINITY).is_none());
    }

    #[test]
    fn aabb_slab_test_handles_axis_parallel_rays() {
        let b = Aabb {
            min: Vec3::splat(-1.0),
            max: Vec3::splat(1.0),
        };
        let d = Vec3::new(0.0, 0.0, -1.0);
        assert_eq!(
            b.hit(Vec3::new(0.5, 0.5, 5.0), d.recip(), f32::INFINITY),
            Some(4.0)
        );
        assert_eq!(
            b.hit(Vec3::new(1.5, 0.5, 5.0), d.recip(), f32::INFINITY),
            None
        );
        assert!(Aabb::EMPTY.is_empty());
        assert_eq!(Aabb::EMPTY.hit(Vec3::ZERO, d.recip(), f32::INFINITY), None);
        // Parallel to y and z, on the box's max-z plane (0·∞ = NaN there) but above its
        // y slab: a miss, whichever axis order the NaN meets (the qbvh engineer's case).
        let plane = Aabb {
            min: Vec3::new(-10.0, 1.54, 0.0),
            max: Vec3::new(10.0, 1.84, 1.796),
        };
        let x = Vec3::X.recip();
        let above = Vec3::new(4.516, 9.584, 1.796);
        assert_eq!(plane.hit(above, x, f32::INFINITY), None);
        assert_eq!(
            plane.hit(above * Vec3::new(-1.0, 1.0, 1.0), x, f32::INFINITY),
            None
        );
        // On the plane and inside the y slab: the NaN axis counts as inside.
        let on = Vec3::new(-12.0, 1.6, 1.796);
        assert_eq!(plane.hit(on, x, f32::INFINITY), Some(2.0));
    }

    /// The branch-free `WatertightRay::new` picks what the paper's construction does:
    /// `kz` the first axis of the largest |d|, `kx`, `ky` the next two cyclically,
    /// swapped where d[kz] < 0, and the same shear and origin bits. Directions include
    /// ties between axes, ±0 components and negative ones.
    #[test]
    fn watertight_ray_axes_as_the_paper_picks_them() {
        let mut rng = crate::sampler::Pcg32::new(5, 17);
        let choices = [0.0, -0.0, 0.5, -0.5, 1.0, -1.0];
        let mut ties = 0;
        for k in 0..20000 {
            let mut c = || {
                if k % 2 == 0 {
                    choices[rng.next_u32() as usize % choices.len()]
                } else {
                    2.0 * rng.uniform_f32() - 1.0
                }
            };
            let d = Vec3::new(c(), c(), c());
            let o = Vec3::new(c(), c(), c()) * 3.0;
            let w = WatertightRay::new(&Ray::new(o, d));
            let kz = d.abs().max_position();
            let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
            if d[kz] < 0.0 {
                std::mem::swap(&mut kx, &mut ky);
            }
            let sz = 1.0 / d[kz];
            let shear = Vec3::new(d[kx] * sz, d[ky] * sz, sz);
            assert_eq!((w.kx, w.ky, w.kz), (kx, ky, kz), "{d:?}");
            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
            assert_eq!(bits(w.shear), bits(shear), "{d:?}");
            assert_eq!(bits(w.o_k), bits(Vec3::new(o[kx], o[ky], o[kz])), "{d:?}");
            ties += (d.abs().max_element() == d.abs().min_element()) as u32;
        }
        // Six values a component on even trials: all three |d| equal in 1/9 of those.
        assert!(ties > 500, "only {ties} ties");
    }

    /// The surface of the cube [-1, 1]³, each face a 4 × 4 grid of quads split into two
    /// triangles (alternating diagonals), vertices shared between faces; with `jitter`,
    /// every vertex moved by up to `jitter` on each axis (the same move wherever it is
    /// shared, so the mesh stays closed and no longer axis-aligned).
    fn closed_cube(rng: &mut crate::sampler::Pcg32, jitter: f32) -> Vec<[Vec3; 3]> {
        let mut moved = std::collections::HashMap::new();
        let mut at = |p: Vec3| {
            let key = (p * 4.0).as_ivec3().to_array();
            *moved.entry(key).or_insert_with(|| {
                let r = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
                p + (r * 2.0 - 1.0) * jitter
            })
        };
        let mut tris = Vec::new();
        for axis in 0..3 {
            for side in [-1.0f32, 1.0] {
                let point = |i: i32, j: i32| {
                    let mut p = [0.0; 3];
                    p[axis] = side;
                    p[(axis + 1) % 3] = -1.0 + 0.5 * i as f32;
                    p[(axis + 2) % 3] = -1.0 + 0.5 * j as f32;
                    Vec3::from(p)
                };
                for i in 0..4 {
                    for j in 0..4 {
                        let [a, b, c, d] = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                            .map(|(i, j)| at(point(i, j)));
                        if (i + j) % 2 == 0 {
                            tris.extend([[a, b, c], [a, c, d]]);
                        } else {
                            tris.extend([[a, b, d], [b, c, d]]);
                        }
                    }
                }
            }
        }
        tris
    }

    /// No ray slips through a closed mesh, above all where it passes exactly through a
    /// shared vertex or edge (edge functions that round to zero, which count as inside):
    /// rays from inside the cube, in any direction and aimed at vertices and edge midpoints, and
    /// rays from outside whose line passes exactly (dyadic coordinates, an unnormalized
    /// direction computed without rounding) through a vertex or an edge's midpoint on its
    /// way to an inside point, all meet the surface; on the jittered cube too. Every hit's
    /// barycentrics lie in [0, 1].
    #[test]
    fn closed_mesh_is_watertight_through_vertices_and_edges() {
        let mut rng = crate::sampler::Pcg32::new(35, 6);
        let mut exact = 0;
        for (mesh_index, jitter) in [0.0f32, 0.1].into_iter().enumerate() {
            let tris = closed_cube(&mut rng, jitter);
            let hits = |ray: &Ray| {
                let w = WatertightRay::new(ray);
                tris.iter()
                    .filter_map(|t| w.intersect(t[0], t[1], t[2], f32::INFINITY))
                    .inspect(|h| {
                        assert!(
                            h.b1 >= 0.0 && h.b2 >= 0.0 && h.b1 + h.b2 <= 1.0 + 1e-6,
                            "{h:?}"
                        )
                    })
                    .count()
            };
            for trial in 0..20000u32 {
                let tri = tris[rng.next_u32() as usize % tris.len()];
                let k = rng.next_u32() as usize % 3;
                // A vertex, or the midpoint of an edge (exact on the plain cube's grid).
                let target = if trial % 2 == 0 {
                    tri[k]
                } else {
                    (tri[k] + tri[(k + 1) % 3]) * 0.5
                };
                let mut grid = |scale: f32| {
                    Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32())
                        .map(|x| ((x * 2.0 - 1.0) * scale * 8.0).round() / 8.0)
                };
                let ray = if trial % 3 == 0 {
                    // From outside, through `target`, on to an inside point `c`: the origin
                    // `target + s (target - c)` and direction `c - target` are exact.
                    let c = grid(0.5);
                    let s = 1.0 + (rng.next_u32() % 4) as f32;
                    let o = target + (target - c) * s;
                    exact += (jitter == 0.0) as u32;
                    Ray::new(o, c - target)
                } else {
                    let o = grid(0.5);
                    Ray::new(o, target - o)
                };
                assert!(
                    hits(&ray) >= 1,
                    "mesh {mesh_index}, trial {trial}: {ray:?} slipped through at {target:?}"
                );
            }
        }
        assert!(exact > 6000, "only {exact} exact rays from outside");
    }
}
