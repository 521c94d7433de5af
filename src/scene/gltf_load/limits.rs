//! Bounds on what a glTF file may contain, checked before anything is trusted.

/// Largest file (glTF JSON, GLB or external buffer) the loader accepts, checked before reading.
pub const MAX_FILE_BYTES: u64 = 2 * 1024 * 1024 * 1024;
/// Largest coordinate magnitude accepted for vertices (object and world space) and cameras:
/// a terametre, far beyond any real scene, yet far enough below `f32::MAX` (~3.4·10³⁸) that
/// bounding boxes, their extents and the ray arithmetic (squared lengths, cross products, BVH
/// slab tests) stay finite.
pub const MAX_COORDINATE: f32 = 1e12;
