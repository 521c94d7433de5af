//! SPIR-V of glsl/*.comp, compiled by build.rs.

pub const TRACE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/trace.spv"));
pub const RAYCAST: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/raycast.spv"));
pub const BRDF_PROBE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/brdf_probe.spv"));
/// trace and raycast with ray queries in place of the software traversal (build.rs).
pub const TRACE_RQ: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/trace_rq.spv"));
/// trace (software, ray query) also writing each lattice point's surface (LATTICE_SURFACE),
/// for the temporal history.
pub const TRACE_SURFACES: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/trace_surfaces.spv"));
pub const TRACE_RQ_SURFACES: &[u8] =
    include_bytes!(concat!(env!("OUT_DIR"), "/trace_rq_surfaces.spv"));
pub const RAYCAST_RQ: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/raycast_rq.spv"));
pub const PLAN: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/plan.spv"));
pub const PLAN_ARGS: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/plan_args.spv"));
pub const RESOLVE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/resolve.spv"));
pub const ACCUMULATE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/accumulate.spv"));
pub const TEMPORAL: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/temporal.spv"));
pub const LATTICE_FILTER: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/lattice_filter.spv"));
pub const DENOISE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/denoise.spv"));
pub const DISPLAY: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/display.spv"));
/// The fill pass of fractional layers, without and with the points' surfaces (history on).
pub const LATTICE_FILL: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/lattice_fill.spv"));
pub const LATTICE_FILL_SURFACES: &[u8] =
    include_bytes!(concat!(env!("OUT_DIR"), "/lattice_fill_surfaces.spv"));
