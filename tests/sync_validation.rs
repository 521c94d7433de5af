//! The validation layer's synchronization checks bite: a pair of dispatches, the second
//! reading what the first wrote, is reported as a hazard without a barrier between them and
//! is clean with one. Every other GPU test runs with the same checks on (tests/common), so a
//! missing barrier anywhere in fovea fails the test that recorded it.

mod common;

use fovea::gpu::shared::*;
use fovea::gpu::{
    shaders, vk, Buffer, ComputePipeline, GpuContext, PipelineLayout, Scope, StorageImage,
};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

const SIZE: u32 = 16;

/// The frame's value at float `i` of its RGBA pixels.
fn frame_value(i: usize) -> f32 {
    (i % 7) as f32
}

/// Accumulate writes a frame into a running mean; merge, a one-layer config, then reads the
/// mean (read-only) and writes it to the frame. Returns what the validation layer reported
/// and the frame merge left.
///
/// A read-only consumer is what makes the pair a read-after-write: the installed layer
/// (1.3.239) classes a storage image that a shader both reads and writes as written only, and
/// does not report a write after such a write.
fn dispatch_pair(ctx: &Arc<GpuContext>, barrier: bool) -> (Vec<String>, Vec<f32>) {
    let layout = PipelineLayout::new(ctx).unwrap();
    let accumulate =
        ComputePipeline::new(ctx, &layout, "accumulate", shaders::ACCUMULATE, &[]).unwrap();
    let merge = ComputePipeline::new(ctx, &layout, "merge", shaders::MERGE, &[]).unwrap();
    let frame = StorageImage::new(ctx, "frame", SIZE, SIZE).unwrap();
    let pixels: Vec<f32> = (0..(SIZE * SIZE * 4) as usize).map(frame_value).collect();
    frame.upload(&pixels).unwrap();
    let means = StorageImage::new_array(ctx, "means", SIZE, SIZE, ACCUM_LAYERS).unwrap();
    means
        .upload(&vec![0.0; (SIZE * SIZE * 4 * ACCUM_LAYERS) as usize])
        .unwrap();
    let buffer = |name, words: &[u32]| {
        let mut b = Buffer::new(
            ctx,
            name,
            (words.len() * 4) as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::CpuToGpu,
        )
        .unwrap();
        b.write(0, bytemuck::cast_slice(words)).unwrap();
        b
    };
    // One layer, all zeros: gaze and view axis forward, no blend band, image layer 0 (the
    // main mean); and no visibility mask.
    let layers = buffer("layers", &vec![0u32; std::mem::size_of::<GpuLayer>() / 4]);
    let visibility = buffer("visibility", &[0]);
    layout.bind(
        &[(BINDING_LAYERS, &layers), (BINDING_VISIBILITY, &visibility)],
        &[(BINDING_OUTPUT, &frame), (BINDING_LAYER_IMAGES, &means)],
    );
    let push = PushConstants {
        width: SIZE,
        height: SIZE,
        layer: ACCUM_LAYER_MAIN,
        layer_count: 1,
        debug: ACCUM_SHOW_NOTHING,
        ..Default::default()
    };
    let groups = |pixels_per_invocation: u32| {
        [
            SIZE.div_ceil(WORKGROUP_SIZE_X * pixels_per_invocation),
            SIZE.div_ceil(WORKGROUP_SIZE_Y),
            1,
        ]
    };
    assert!(ctx.take_validation_messages().is_empty());
    ctx.submit_and_wait("dispatch pair", |cmd| {
        accumulate.cmd_dispatch(cmd, &layout, &push, groups(1));
        if barrier {
            ctx.cmd_barrier(cmd, Scope::COMPUTE_WRITE, Scope::COMPUTE_READ_WRITE);
        }
        // Merge's debug 0: the image itself.
        let push = PushConstants { debug: 0, ..push };
        merge.cmd_dispatch(cmd, &layout, &push, groups(PIXELS_PER_INVOCATION));
    })
    .unwrap();
    let messages = ctx.take_validation_messages();
    (messages, frame.read_back().unwrap())
}

#[test]
fn a_missing_barrier_is_reported_as_a_hazard() {
    let ctx = common::context();
    let (messages, _) = dispatch_pair(&ctx, false);
    assert!(
        messages
            .iter()
            .any(|m| m.contains("SYNC-HAZARD-READ-AFTER-WRITE")),
        "no read-after-write hazard reported for two dispatches without a barrier; messages:\n{}",
        messages.join("\n")
    );
}

#[test]
fn the_barrier_removes_the_hazard() {
    let ctx = common::context();
    let (messages, frame) = dispatch_pair(&ctx, true);
    assert!(
        messages.is_empty(),
        "validation messages with the barrier in place:\n{}",
        messages.join("\n")
    );
    // The mean of one frame is the frame, and merge of the one layer copies it back.
    for (i, pixel) in frame.chunks_exact(4).enumerate() {
        let expected: Vec<f32> = (0..3).map(|c| frame_value(i * 4 + c)).collect();
        assert_eq!(&pixel[..3], &expected[..], "pixel {i}");
    }
}
