//! Which renderer made an image: the crate's version and the shaders a reference frame runs.
//! A changed integrator, traversal or resolve changes the SPIR-V and so this fingerprint,
//! which keys cached references (bench/quality.rs).

use crate::gpu::shaders;
use crate::scene::fingerprint::Fingerprint;

/// The fingerprint of this build's renderer.
pub fn renderer_version() -> u64 {
    [
        shaders::TRACE,
        shaders::TRACE_RQ,
        shaders::TRACE_SURFACES,
        shaders::TRACE_RQ_SURFACES,
        shaders::PLAN,
        shaders::PLAN_ARGS,
        shaders::RESOLVE,
    ]
    .iter()
    .fold(
        Fingerprint::default().bytes(env!("CARGO_PKG_VERSION").as_bytes()),
        |f, spirv| f.bytes(spirv),
    )
    .value()
}
