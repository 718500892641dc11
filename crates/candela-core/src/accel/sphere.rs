//! The sphere test of [`intersect_sphere`] on a register of sphere lanes at once, so
//! that a block of spheres costs one vector test as a block of triangles does, not one
//! scalar test a sphere (the issue-35 profile: sphere tests 10–24 % of sphere scenes'
//! time, one at a time).
//!
//! Every lane performs the scalar test's operations in its order: the dot products as
//! glam sums them (`x·x + y·y + z·z`, left to right), plain IEEE add, subtract, multiply,
//! divide and square root (correctly rounded in both, never fused), so a lane's distance
//! is the same bits as [`intersect_sphere`] gives (`block.rs`'s test compares them).

#![cfg(target_arch = "x86_64")]

use super::lanes::Wide;
#[cfg(doc)]
use crate::geometry::intersect_sphere;
use crate::geometry::Ray;

/// [`intersect_sphere`] on `V::LANES` spheres: `centre` the rows of their centres'
/// x, y and z, `radius` the row of their radii. Returns the lanes hit within
/// (ε, t_max) as all-ones lanes, and there the distance, the nearer root where it is in
/// range, else the farther one. Other lanes' distances are unspecified. Lanes outside
/// `lanes` (bit i for lane i) may be reported hit: the caller masks them off.
///
/// Where no lane of `lanes` has a discriminant ≥ 0 (the ray misses every sphere: the
/// scalar test's early `None`), the roots are not computed and no lane is hit (about
/// 30 of the test's 75 instructions; most sphere lanes a ray meets are misses).
///
/// # Safety
/// The CPU must support `V`, and each row must hold `V::LANES` readable floats.
#[inline(always)]
pub(super) unsafe fn intersect_spheres<V: Wide>(
    ray: &Ray,
    centre: [*const f32; 3],
    radius: *const f32,
    t_max: f32,
    lanes: u32,
) -> (V, V) {
    let d = ray.d;
    // The ray's terms are the scalar test's own scalars, splatted.
    let a = d.length_squared();
    let (dx, dy, dz) = (V::splat(d.x), V::splat(d.y), V::splat(d.z));
    let ox = V::splat(ray.o.x).sub(V::load(centre[0]));
    let oy = V::splat(ray.o.y).sub(V::load(centre[1]));
    let oz = V::splat(ray.o.z).sub(V::load(centre[2]));
    let r = V::load(radius);
    let b = V::splat(2.0).mul(dx.mul(ox).add(dy.mul(oy)).add(dz.mul(oz)));
    let c = ox.mul(ox).add(oy.mul(oy)).add(oz.mul(oz)).sub(r.mul(r));
    // The origin's offset from the line's closest point, for a discriminant that keeps
    // its precision far from the sphere (as the scalar test).
    let s = b.div(V::splat(2.0 * a));
    let vx = ox.sub(s.mul(dx));
    let vy = oy.sub(s.mul(dy));
    let vz = oz.sub(s.mul(dz));
    let len = vx.mul(vx).add(vy.mul(vy)).add(vz.mul(vz)).sqrt();
    let discrim = V::splat(4.0 * a).mul(r.add(len)).mul(r.sub(len));
    let zero = V::splat(0.0);
    if discrim.ge(zero).bits() & lanes == 0 {
        return (zero, zero);
    }
    // A negative discriminant's root is NaN, and so are both distances, which no
    // comparison below passes: the scalar test's early `None`.
    let root = discrim.sqrt();
    let half = V::splat(-0.5);
    let q = b
        .lt(zero)
        .select(half.mul(b.sub(root)), half.mul(b.add(root)));
    let t0 = q.div(V::splat(a));
    let t1 = c.div(q);
    let swap = t0.gt(t1);
    let (near, far) = (swap.select(t1, t0), swap.select(t0, t1));
    let eps = V::splat(1e-4).mul(r);
    let t_max = V::splat(t_max);
    let near_ok = near.gt(eps).and(near.lt(t_max));
    let far_ok = far.gt(eps).and(far.lt(t_max));
    (near_ok.or(far_ok), near_ok.select(near, far))
}
