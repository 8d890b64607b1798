//! The sizes of a height map that bound its files, apart so that the reader
//! ([`super::input`], whose caps they are) and the height map files ([`super::height_map`],
//! which re-exports them) both take them from below.

/// Largest number of rows and of columns of a height map, and of pixels per line and of lines
/// of an image ([`crate::request::image`]).
pub const MAX_PIXELS: usize = 4096;

/// Largest height map CSV file read, in bytes: 512 MiB, 32 bytes for each of 4096 × 4096
/// values (a full-precision height and its comma take 24).
pub const MAX_CSV_BYTES: u64 = (MAX_PIXELS * MAX_PIXELS * 32) as u64;

/// Largest NPY header read, in bytes (NumPy's own `np.load` allows 10 000).
pub const MAX_NPY_HEADER_BYTES: usize = 65_536;

/// Largest NPY height map file read, in bytes: 4096 × 4096 float64 values and the largest
/// header.
pub const MAX_NPY_BYTES: u64 = (MAX_PIXELS * MAX_PIXELS * 8 + MAX_NPY_HEADER_BYTES + 12) as u64;
