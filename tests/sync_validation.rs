//! The validation layer's synchronization checks bite: a copy into the lattice values and the
//! resolve dispatch reading them is reported as a hazard without a barrier between them and
//! is clean with one. Every other GPU test runs with the same checks on (tests/common), so a
//! missing barrier anywhere in fovea fails the test that recorded it.

mod common;

use fovea::gpu::{
    shaders, vk, Bound, Buffer, ComputePipeline, DescriptorArena, EyeTexels, GpuContext,
    PipelineLayout, Scope,
};
use fovea::shader_layout::*;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

const SIZE: u32 = 16;

/// The lattice's value at float `i` of its RGBA points.
fn lattice_value(i: usize) -> f32 {
    (i % 7) as f32
}

/// A copy writes the lattice values of a one-layer, spacing-1 config; resolve then reads them
/// (LATTICE is read-only there) into the frame. Returns what the validation layer reported
/// and the frame resolve wrote.
fn copy_then_resolve(ctx: &Arc<GpuContext>, barrier: bool) -> (Vec<String>, Vec<f32>) {
    let layout = PipelineLayout::new(ctx).unwrap();
    let resolve = ComputePipeline::new(ctx, &layout, "resolve", shaders::RESOLVE, &[]).unwrap();
    let frame = Buffer::new(
        ctx,
        "frame pixels",
        (SIZE * SIZE * 16) as u64,
        vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
        MemoryLocation::GpuOnly,
    )
    .unwrap();
    let host = |name, bytes: &[u8], usage| {
        let mut b = Buffer::new(
            ctx,
            name,
            bytes.len() as u64,
            usage,
            MemoryLocation::CpuToGpu,
        )
        .unwrap();
        b.write(0, bytes).unwrap();
        b
    };
    let values: Vec<f32> = (0..(SIZE * SIZE * 4) as usize).map(lattice_value).collect();
    let staging = host(
        "staging",
        bytemuck::cast_slice(&values),
        vk::BufferUsageFlags::TRANSFER_SRC,
    );
    let lattice = Buffer::new(
        ctx,
        "lattice",
        staging.size,
        vk::BufferUsageFlags::STORAGE_BUFFER
            | vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER
            | vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuOnly,
    )
    .unwrap();
    // Resolve reads the values through a texel view of the same buffer (one per eye).
    let lattice_texels = EyeTexels::of_frame(&lattice, "lattice", 1, lattice.size / 16).unwrap();
    // One layer without limits: every pixel is its lattice point, row-major from (0, 0).
    let layer = GpuLayer {
        gaze: [0.0, 0.0, 1.0, 0.0],
        resolve_cos: [-2.0, -2.0, -2.0, 0.0],
        pixel_tan: [-0.5, -0.5, 1.0 / SIZE as f32, 1.0 / SIZE as f32],
        spacing: 1,
        spp: 1,
        box_cols: SIZE,
        box_rows: SIZE,
        cols: SIZE,
        outer: NO_LIMIT,
        ..Default::default()
    };
    let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
    let layers = host("layers", bytemuck::bytes_of(&layer), storage);
    let visibility = host("visibility", &0u32.to_le_bytes(), storage);
    let mut descriptors = DescriptorArena::new(ctx).unwrap();
    let set = descriptors
        .set(
            &layout,
            &[
                (BINDING_LAYERS, Bound::Storage(&layers)),
                (BINDING_VISIBILITY, Bound::Storage(&visibility)),
                (BINDING_LATTICE, Bound::Storage(&lattice)),
                (BINDING_PIXELS, Bound::Storage(&frame)),
                (BINDING_LATTICE_TEXELS, Bound::EyeTexels(&lattice_texels)),
            ],
        )
        .unwrap();
    let push = EyePush {
        eye: PushEye {
            width: SIZE,
            height: SIZE,
            layer_count: 1,
            ..Default::default()
        },
        ..Default::default()
    };
    let groups = [
        SIZE.div_ceil(PIXELS_PER_INVOCATION)
            .div_ceil(WORKGROUP_SIZE_X),
        SIZE.div_ceil(WORKGROUP_SIZE_Y),
        1,
    ];
    assert!(ctx.take_validation_messages().is_empty());
    ctx.submit_and_wait("copy and resolve", |cmd| {
        staging.cmd_copy_to(cmd, &lattice, staging.size);
        if barrier {
            ctx.cmd_barrier(cmd, Scope::COPY_WRITE, Scope::COMPUTE_READ);
        }
        resolve.cmd_dispatch(cmd, &layout, set, &push, groups);
    })
    .unwrap();
    let messages = ctx.take_validation_messages();
    let pixels = bytemuck::pod_collect_to_vec(&frame.read_back().unwrap());
    (messages, pixels)
}

#[test]
fn a_missing_barrier_is_reported_as_a_hazard() {
    let ctx = common::context();
    let (messages, _) = copy_then_resolve(&ctx, false);
    assert!(
        messages
            .iter()
            .any(|m| m.contains("SYNC-HAZARD-READ-AFTER-WRITE")),
        "no read-after-write hazard reported for a copy and a dispatch without a barrier; messages:\n{}",
        messages.join("\n")
    );
}

#[test]
fn the_barrier_removes_the_hazard() {
    let ctx = common::context();
    let (messages, frame) = copy_then_resolve(&ctx, true);
    assert!(
        messages.is_empty(),
        "validation messages with the barrier in place:\n{}",
        messages.join("\n")
    );
    // Resolve of one spacing-1 layer copies its lattice values.
    for (i, pixel) in frame.chunks_exact(4).enumerate() {
        let expected: Vec<f32> = (0..3).map(|c| lattice_value(i * 4 + c)).collect();
        assert_eq!(&pixel[..3], &expected[..], "pixel {i}");
    }
}
