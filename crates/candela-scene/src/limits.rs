//! How much memory a file may make Candela allocate.
//!
//! A renderer is handed files from everywhere, and a header is a promise the file need
//! not keep: a 100-byte PNG may claim 100000×100000 pixels, a PLY four billion vertices.
//! Every loader checks what a header declares against the file's size *before*
//! allocating for it, so that decoding a file of `n` bytes allocates at most
//! [`allocation_budget`]`(n)` = **64 × n + 256 MiB**.
//!
//! The multiple covers what honest files need — a binary PLY vertex of 12 bytes becomes
//! a parsed element and a mesh vertex; an RGBE pixel of 4 bytes a float RGB one of 12,
//! twice over while it is converted — and the constant lets a small, well-compressed
//! image (a 2048² PNG of one colour is a few kilobytes) still load. Formats whose
//! compression can beat 64:1 (PNG, EXR) are held to the budget by their declared
//! dimensions: pixels × [`PEAK_BYTES_PER_PIXEL`] must fit in it.
//!
//! The fuzz targets (`fuzz/`) run every parser under an allocator that aborts when a
//! single input makes the live heap grow past this budget.

/// Bytes a file of `file_len` bytes may make a loader allocate: 64 × its size + 256 MiB.
pub fn allocation_budget(file_len: usize) -> u64 {
    ALLOCATION_MULTIPLE
        .saturating_mul(file_len as u64)
        .saturating_add(ALLOCATION_SLACK)
}

/// The multiple of a file's size a loader may allocate.
pub const ALLOCATION_MULTIPLE: u64 = 64;

/// What a loader may allocate beyond the multiple of the file's size.
pub const ALLOCATION_SLACK: u64 = 256 << 20;

/// The most bytes decoding allocates per pixel at its peak: the decoder's buffer (at
/// most RGBA in f32, 16 bytes), the f32 RGB copy (12) and the linear image (12).
pub const PEAK_BYTES_PER_PIXEL: u64 = 40;

/// Checks that an image of `width × height` pixels, declared by a file of `file_len`
/// bytes, can be decoded within the file's [`allocation_budget`].
pub fn check_image_size(width: u64, height: u64, file_len: usize) -> Result<(), String> {
    let need = (width as u128) * (height as u128) * PEAK_BYTES_PER_PIXEL as u128;
    let budget = allocation_budget(file_len);
    if need > budget as u128 {
        return Err(format!(
            "the header declares {width}x{height} pixels, which would need {} MiB to decode; \
             a file of {file_len} bytes may use at most {} MiB (64 × its size + 256 MiB)",
            need >> 20,
            budget >> 20
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_budget_is_64_times_the_size_plus_256_mib() {
        assert_eq!(allocation_budget(0), 256 << 20);
        assert_eq!(allocation_budget(1 << 20), (64 + 256) << 20);
    }

    #[test]
    fn image_sizes_are_checked_against_the_budget() {
        // 4096² fits the constant alone (640 MiB > 256 MiB does not): 2048² does.
        assert!(check_image_size(2048, 2048, 100).is_ok());
        assert!(check_image_size(4096, 4096, 100).is_err());
        assert!(check_image_size(4096, 4096, 8 << 20).is_ok());
        let e = check_image_size(100_000, 100_000, 100).unwrap_err();
        assert!(e.contains("100000x100000"), "{e}");
        assert!(check_image_size(u64::MAX, u64::MAX, usize::MAX).is_err());
    }
}
