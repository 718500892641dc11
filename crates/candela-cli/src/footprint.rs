//! Where a big scene's time and memory go: the process's peak resident memory and the
//! bytes the built scene holds, for the render summary and `candela info`.

use candela_core::accel::LeafLayout;
use candela_core::scene::{Mesh, Scene};

/// The process's peak resident set so far in bytes (`VmHWM` of `/proc/self/status`), or
/// `None` where the system does not report it.
pub fn peak_resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Bytes of a built scene's geometry and acceleration structures.
#[derive(Clone, Copy, Debug, Default)]
pub struct SceneMemory {
    /// Vertex attributes, indices and per-triangle data of the meshes (instanced ones
    /// once).
    pub meshes: usize,
    /// The primitive table and the wide BVHs' nodes and triangle blocks (top level and
    /// instance levels).
    pub accel: usize,
}

impl SceneMemory {
    pub fn of(scene: &Scene) -> SceneMemory {
        let meshes = scene
            .meshes
            .iter()
            .chain(&scene.instances.meshes)
            .map(mesh_bytes)
            .sum();
        let accels = std::iter::once(&scene.accel).chain(&scene.instances.blas);
        let accel = accels.map(|a| a.memory().0 + a.memory().1).sum::<usize>()
            + size_of_val(&scene.prims[..]);
        SceneMemory { meshes, accel }
    }

    pub fn total(&self) -> usize {
        self.meshes + self.accel
    }
}

fn mesh_bytes(m: &Mesh) -> usize {
    size_of_val(&m.positions[..])
        + size_of_val(&m.normals[..])
        + size_of_val(&m.uvs[..])
        + size_of_val(&m.colors[..])
        + size_of_val(&m.tangents[..])
        + size_of_val(&m.indices[..])
        + size_of_val(&m.lights[..])
        + size_of_val(&m.face_normals[..])
        + size_of_val(&m.face_dpdu[..])
}

/// The peak after loading and after building, and the process's peak now: which phase
/// set it ("peak memory 817.8 MB (load 288.0 MB, build 817.8 MB)").
pub fn peaks(load: Option<u64>, build: Option<u64>) -> String {
    let Some(total) = peak_resident_bytes() else {
        return "unknown".into();
    };
    let phase = |name: &str, bytes: Option<u64>| bytes.map(|b| format!("{name} {}", megabytes(b)));
    let phases: Vec<String> = [phase("load", load), phase("build", build)]
        .into_iter()
        .flatten()
        .collect();
    format!("{} ({})", megabytes(total), phases.join(", "))
}

/// "123.4 MB".
pub fn megabytes(bytes: u64) -> String {
    format!("{:.1} MB", bytes as f64 / 1e6)
}

/// The scene's memory on one line: total, per stored triangle, and its parts.
pub fn describe(scene: &Scene) -> String {
    let m = SceneMemory::of(scene);
    let triangles = scene.stored_triangle_count().max(1);
    let leaves = match scene.accel.layout().leaves {
        LeafLayout::Inline => "inline",
        LeafLayout::Indexed => "compact",
    };
    format!(
        "{} ({:.0} bytes a triangle: meshes {}, acceleration {}, {leaves} leaves)",
        megabytes(m.total() as u64),
        m.total() as f64 / triangles as f64,
        megabytes(m.meshes as u64),
        megabytes(m.accel as u64)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn peak_memory_is_reported_and_grows_with_what_is_touched() {
        let Some(before) = peak_resident_bytes() else {
            eprintln!("skipped: no /proc/self/status on this system");
            return;
        };
        // Touch 64 MB: the peak must cover it.
        let block = vec![1u8; 64 << 20];
        let after = peak_resident_bytes().unwrap();
        assert!(
            after >= before && after >= block.len() as u64,
            "{before} -> {after}"
        );
        assert_eq!(block.iter().map(|&b| b as usize).sum::<usize>(), 64 << 20);
    }

    #[test]
    fn a_scene_counts_its_mesh_bytes() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell.toml");
        let desc = candela_scene::load_scene(std::path::Path::new(path)).unwrap();
        let scene = candela_core::build::build_owned(desc).unwrap();
        let m = SceneMemory::of(&scene);
        // At least the positions and indices of every triangle, and one block of eight.
        let triangles = scene.stored_triangle_count();
        assert!(m.meshes >= triangles * 12 + triangles * 12 / 3, "{m:?}");
        assert!(m.accel >= triangles * 4, "{m:?}");
        assert!(describe(&scene).contains("bytes a triangle"));
    }
}
