//! SPIR-V of glsl/*.comp, compiled by build.rs.

pub const TRACE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/trace.spv"));
pub const RAYCAST: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/raycast.spv"));
pub const INTERPOLATE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/interpolate.spv"));
pub const MERGE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/merge.spv"));
pub const ACCUMULATE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/accumulate.spv"));
