//! GPU-assisted validation (shaders instrumented by the validation layer to report
//! out-of-bounds descriptor accesses) over every fovea shader, on lavapipe: it reports an
//! access past the end of a buffer, and each shader runs clean under it. Instrumented shaders
//! run thousands of times slower on lavapipe, so the dispatches are tiny.

mod common;

use fovea::foveation::{FoveationConfig, Gaze, GazeChoice};
use fovea::gpu::{
    shaders, vk, Bound, Buffer, ComputePipeline, DescriptorArena, EyeTexels, PipelineLayout,
    StorageImage,
};
use fovea::render::accumulate::{AccumulateRequest, Accumulator, Mean, Show};
use fovea::render::FrameOptions;
use fovea::render::{eye_views, DebugView, FovChoice, FrameRequest, Renderer};
use fovea::scene::builtin::builtin;
use fovea::shader_layout::*;
use gpu_allocator::MemoryLocation;

const SIZE: u32 = 8;

/// Resolve reads each layer's parameters (a GpuLayer, 128 bytes) from a 16-byte buffer: the
/// instrumented shader reports the access past its end.
#[test]
fn an_out_of_bounds_read_is_reported() {
    let ctx = common::gpu_assisted_context();
    let layout = PipelineLayout::new(&ctx).unwrap();
    let resolve = ComputePipeline::new(&ctx, &layout, "resolve", shaders::RESOLVE, &[]).unwrap();
    let frame = StorageImage::new(&ctx, "frame", SIZE, SIZE).unwrap();
    frame.upload(&[0.0; (SIZE * SIZE * 4) as usize]).unwrap();
    let small = |name| {
        Buffer::new(
            &ctx,
            name,
            16,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER,
            MemoryLocation::CpuToGpu,
        )
        .unwrap()
    };
    let (layers, visibility) = (small("too small for a layer"), small("no mask"));
    let lattice = small("lattice");
    let lattice_texels = EyeTexels::of_frame(&lattice, "lattice", 1, 1).unwrap();
    let mut descriptors = DescriptorArena::new(&ctx).unwrap();
    let set = descriptors
        .set(
            &layout,
            &[
                (BINDING_LAYERS, Bound::Storage(&layers)),
                (BINDING_VISIBILITY, Bound::Storage(&visibility)),
                (BINDING_LATTICE, Bound::Storage(&lattice)),
                (BINDING_OUTPUT, Bound::Image(&frame)),
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
    ctx.submit_and_wait("out of bounds", |cmd| {
        resolve.cmd_dispatch(cmd, &layout, set, &push, [1, 1, 1])
    })
    .unwrap();
    let messages = ctx.take_validation_messages();
    assert!(
        messages
            .iter()
            .any(|m| m.contains("out of bounds") && m.contains("Descriptor size is 16")),
        "no out-of-bounds report from GPU-assisted validation; messages:\n{}",
        messages.join("\n")
    );
}

/// plan, dispatch sizes, trace, fill and resolve: a foveated stereo frame (every layer, both
/// eyes, two of them fractional);
/// accumulate: that frame added to a running mean and shown as the heat map (which reads
/// every layer's parameters); raycast: a few probe rays.
#[test]
fn every_shader_runs_clean_under_gpu_assisted_validation() {
    let ctx = common::gpu_assisted_context();
    let scene = builtin("cornell", 1.0).unwrap();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    // The accumulator reads the frames from the output image.
    renderer.set_output_image(true);
    // The thesis' layers, two of them tracing a fraction of their points: the fill runs too.
    let mut thesis = FoveationConfig::thesis();
    (thesis.layers[0].fraction, thesis.layers[2].fraction) = (2, 4);
    let gaze = GazeChoice {
        left: Gaze::Corner,
        right: Gaze::Forward,
    };
    let eyes = eye_views(&scene.camera, 1.0, FovChoice::Scene, true, gaze);
    let settings = common::settings(SIZE, SIZE, 1, 1, fovea::render::Integrator::Pt);
    let frame = renderer
        .frame(
            &FrameRequest {
                settings,
                foveation: &thesis,
                eyes: &eyes,
                debug: DebugView::None,
            },
            FrameOptions::measure(),
        )
        .map(Option::unwrap)
        .unwrap();
    let passes: Vec<&str> = frame.stats.pass_ms.iter().map(|p| p.0.as_str()).collect();
    for pass in [
        "left plan",
        "right plan",
        "dispatch sizes",
        "left trace",
        "right trace",
        "left lattice fill",
        "right lattice fill",
        "left resolve",
        "right resolve",
        "output image",
    ] {
        assert!(passes.contains(&pass), "{pass} did not run: {passes:?}");
    }
    common::assert_no_validation_messages(&ctx);

    let mut means = Accumulator::new(&ctx).unwrap();
    means
        .add(&AccumulateRequest {
            frame: renderer.output_image().unwrap(),
            eyes: &eyes,
            eye_size: [SIZE, SIZE],
            foveation: &thesis,
            into: Mean::Main,
            show: Show::Heat,
        })
        .unwrap();
    common::assert_no_validation_messages(&ctx);

    let toward = |x: f32| GpuProbeRay {
        origin: [
            scene.camera.position.x,
            scene.camera.position.y,
            scene.camera.position.z,
            0.0,
        ],
        direction: [x, 0.0, -1.0, f32::INFINITY],
    };
    let (hits, overflows) = renderer.raycast(&[toward(-0.1), toward(0.1)]).unwrap();
    assert_eq!((hits.len(), overflows), (2, 0));
    common::assert_no_validation_messages(&ctx);
}
