//! What `fovea render` prints about a frame: each eye's gaze, the samples per layer, CPU and
//! GPU time per pass, rays, and the BVH traversal profile with `--profile-traversal`.

use fovea::foveation::FoveationConfig;
use fovea::render::{Frame, RenderSettings, TraversalCounts};

/// Prints what the frame traced, per layer, and what it cost.
pub fn report(
    frame: &Frame,
    config: &FoveationConfig,
    settings: &RenderSettings,
    subgroup_size: u32,
) {
    let s = &frame.stats;
    for (e, (gaze, fix)) in frame.gazes.iter().enumerate() {
        let which = match (frame.gazes.len(), e) {
            (1, _) => "eye",
            (_, 0) => "left eye",
            _ => "right eye",
        };
        println!(
            "{which}: gaze at pixel ({:.1}, {:.1}){}",
            gaze[0],
            gaze[1],
            match fix {
                fovea::foveation::gaze::GazeFix::None => "",
                fovea::foveation::gaze::GazeFix::NotFinite =>
                    " (requested gaze not finite: view axis used)",
                fovea::foveation::gaze::GazeFix::Clamped =>
                    " (requested gaze off the image: clamped to its border)",
            }
        );
    }
    println!(
        "{:<6} {:>8} {:>8} {:>5} {:>9} {:>12}",
        "layer", "radius", "spacing", "spp", "per frame", "samples"
    );
    for (k, (layer, samples)) in config.layers.iter().zip(&s.layer_samples).enumerate() {
        let radius = layer
            .radius_deg
            .map_or("rest".to_string(), |r| format!("{r}°"));
        // The share of its lattice points the layer traces per frame (`fraction`).
        let share = match layer.fraction {
            1 => "all".to_string(),
            n => format!("1/{n}"),
        };
        println!(
            "{:<6} {:>8} {:>8} {:>5} {:>9} {:>12}",
            k + 1,
            radius,
            layer.spacing,
            layer.spp,
            share,
            samples
        );
    }
    if s.filled_points > 0 {
        println!(
            "lattice points filled from their traced neighbours: {}",
            s.filled_points
        );
    }
    let planned: u64 = s.layer_samples.iter().sum();
    let full = frame.width as u64 * frame.height as u64 * settings.spp as u64;
    println!(
        "samples traced: {planned} ({:.2}% of a regular frame's {full}); CPU: planned in {:.3} ms, recorded in {:.3} ms",
        100.0 * planned as f64 / full as f64,
        s.plan_ms,
        s.record_ms
    );
    for (pass, ms) in &s.pass_ms {
        println!("gpu pass {pass}: {ms:.2} ms");
    }
    println!(
        "{}x{} {:?}, {} traversal: {:.2} ms GPU, {:.2} Msamples/s, {} rays ({:.2} Mrays/s)",
        frame.width,
        frame.height,
        settings.integrator,
        s.traced_with.name(),
        s.gpu_ms(),
        s.msamples_per_s(),
        s.rays,
        s.rays as f64 / (s.gpu_ms() * 1e3).max(1e-9)
    );
    println!(
        "non-finite samples dropped: {}, BVH stack overflows: {}",
        s.nonfinite_samples, s.stack_overflows
    );
    if let Some(t) = &s.traversal {
        report_traversal(t, s.rays, subgroup_size);
    }
}

/// The traversal profile per ray, and the traversal loop's SIMD occupancy at each BVH level.
fn report_traversal(t: &TraversalCounts, rays: u64, subgroup_size: u32) {
    let per_ray = |n: u64| n as f64 / rays.max(1) as f64;
    println!(
        "traversal per ray: {:.2} TLAS nodes, {:.2} BLAS nodes, {:.2} triangle tests, {:.2} box/sphere tests, {:.2} TLAS steps, {:.2} BLAS steps",
        per_ray(t.tlas_nodes),
        per_ray(t.blas_nodes),
        per_ray(t.triangles),
        per_ray(t.primitives),
        per_ray(t.tlas_lane_steps),
        per_ray(t.blas_lane_steps),
    );
    let occupancy = |lane, group| {
        TraversalCounts::occupancy(lane, group, subgroup_size)
            .map_or("-".to_string(), |o| format!("{:.1}%", 100.0 * o))
    };
    println!(
        "traversal SIMD occupancy ({subgroup_size} lanes): TLAS level {}, BLAS level {}",
        occupancy(t.tlas_lane_steps, t.tlas_group_steps),
        occupancy(t.blas_lane_steps, t.blas_group_steps),
    );
}
