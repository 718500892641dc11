//! What every fuzz target shares: an allocator that holds each input to Candela's
//! allocation budget ([`candela_scene::limits::allocation_budget`]: 64 × its size +
//! 256 MiB) and aborts — a crash libFuzzer records — when an input makes the live heap
//! grow past it. Without a sanitizer libFuzzer cannot see a huge allocation that is
//! never touched (overcommit hands it out for free), so this is what catches a header
//! that makes a loader reserve gigabytes.

use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Write;
use std::sync::atomic::{AtomicU64, Ordering};

struct Budgeted;

/// Live heap bytes of the Rust side (libFuzzer's own C++ heap is not counted).
static LIVE: AtomicU64 = AtomicU64::new(0);
/// The live bytes at which to abort: the input's budget above what was live before it.
static CEILING: AtomicU64 = AtomicU64::new(u64::MAX);

unsafe impl GlobalAlloc for Budgeted {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        grow(layout.size());
        System.alloc(layout)
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        grow(layout.size());
        System.alloc_zeroed(layout)
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size() as u64, Ordering::Relaxed);
        System.dealloc(ptr, layout)
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size >= layout.size() {
            grow(new_size - layout.size());
        } else {
            LIVE.fetch_sub((layout.size() - new_size) as u64, Ordering::Relaxed);
        }
        System.realloc(ptr, layout, new_size)
    }
}

fn grow(bytes: usize) {
    let live = LIVE.fetch_add(bytes as u64, Ordering::Relaxed) + bytes as u64;
    if live > CEILING.load(Ordering::Relaxed) {
        // No allocation from here on: write the message straight to stderr and abort.
        let _ = std::io::stderr().write_all(
            b"candela-fuzz: the input made the heap grow past its allocation budget \
              (64 x its size + 256 MiB)\n",
        );
        std::process::abort();
    }
}

#[global_allocator]
static ALLOCATOR: Budgeted = Budgeted;

/// Runs `parse` on one input under the input's allocation budget.
pub fn with_budget<R>(data: &[u8], parse: impl FnOnce(&[u8]) -> R) -> R {
    let budget = candela_scene::limits::allocation_budget(data.len());
    CEILING.store(
        LIVE.load(Ordering::Relaxed).saturating_add(budget),
        Ordering::Relaxed,
    );
    let result = parse(data);
    CEILING.store(u64::MAX, Ordering::Relaxed);
    result
}

/// A parser's result must be an error that is one line, with a location, never a panic
/// (a panic aborts the process, which libFuzzer records as a crash).
pub fn check_message(message: &str) {
    assert!(
        !message.contains('\n'),
        "error message is not one line: {message:?}"
    );
    assert!(!message.is_empty(), "empty error message");
}

/// Where a scene target's input sits: a file (never read) in the repository's `scenes/`,
/// so that what an input names relative to it is there to load — the media example's
/// grid `media/smoke.vol`, the Cornell meshes — and the loaders behind the scene
/// formats (`.vol` grids, meshes) run on real data too.
pub fn scene_path(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenes")
        .join(name)
}
