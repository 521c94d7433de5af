//! glTF's doubleSided and alpha (MASK, BLEND) in both traversals: which rays meet which
//! surfaces, checked hit by hit through the ray-cast probe, and the check the issue asks
//! for: an alpha-cut card casts the shadow of the same shape made of geometry.

mod common;

use fovea::render::{regular_frame, Integrator, Renderer, Traversal};
use fovea::scene::gltf_samples::checker_alpha;
use fovea::scene::shapes::quad;
use fovea::scene::{
    AlphaMode, Camera, Coverage, Environment, Instance, Material, Mesh, MetallicRoughness, Scene,
    Sphere, Texture, TextureRef, VertexShading,
};
use fovea::shader_layout::{GpuProbeHit, GpuProbeRay};
use glam::{Mat4, Vec3};

const TRAVERSALS: [Traversal; 2] = [Traversal::Software, Traversal::RayQuery];

fn white(coverage: Coverage) -> Material {
    Material::MetallicRoughness(MetallicRoughness {
        coverage,
        ..MetallicRoughness::factors(Vec3::ONE, 0.0, 1.0, Vec3::ZERO)
    })
}

fn with_texture(material: Material) -> Material {
    let Material::MetallicRoughness(mut m) = material else {
        unreachable!()
    };
    m.textures.base_color = Some(TextureRef {
        texture: 0,
        texcoord: 0,
        transform: TextureRef::IDENTITY,
    });
    Material::MetallicRoughness(m)
}

/// 4 × 4 white texels, alpha a checkerboard (opaque where x + y is even), read exactly.
fn checker() -> Texture {
    checker_alpha(4)
}

fn scene(instances: Vec<Instance>, materials: Vec<Material>) -> Scene {
    Scene {
        name: "coverage".into(),
        meshes: vec![quad()],
        instances,
        boxes: vec![],
        spheres: vec![],
        materials,
        textures: vec![checker()],
        camera: Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 40.0, 1.0),
        environment: Environment::black(),
        lights: Vec::new(),
        environment_map: None,
        light_selection: Default::default(),
    }
}

fn placed(material: u32, transform: Mat4) -> Instance {
    Instance {
        mesh: 0,
        material,
        transform,
    }
}

fn ray(origin: Vec3, direction: Vec3) -> GpuProbeRay {
    GpuProbeRay {
        origin: [origin.x, origin.y, origin.z, 0.0],
        direction: [direction.x, direction.y, direction.z, f32::INFINITY],
    }
}

fn cast(scene: &Scene, traversal: Traversal, rays: &[GpuProbeRay]) -> Vec<GpuProbeHit> {
    let ctx = common::context();
    let mut renderer = Renderer::new(&ctx, scene).expect("scene upload");
    renderer.set_traversal(traversal).unwrap();
    let (hits, overflows) = renderer.raycast(rays).unwrap();
    assert_eq!(overflows, 0);
    drop(renderer);
    common::assert_no_validation_messages(&ctx);
    hits
}

#[test]
fn a_single_sided_surface_is_missing_from_behind_and_a_mirror_keeps_its_front() {
    let single = Coverage {
        double_sided: false,
        ..Coverage::SOLID
    };
    let at = |x: f32| Mat4::from_translation(Vec3::new(x, 0.0, 0.0));
    let scene = scene(
        vec![
            placed(0, at(-3.0)),                                              // single-sided
            placed(1, at(0.0)),                                               // double-sided
            placed(0, at(3.0) * Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0))), // mirrored
            placed(0, at(6.0) * Mat4::from_rotation_y(std::f32::consts::PI)), // facing -z
        ],
        vec![white(single), white(Coverage::SOLID)],
    );
    // From +z (toward -z), then from -z, at each quad's centre (a little off its diagonal).
    let rays: Vec<GpuProbeRay> = [5.0f32, -5.0]
        .iter()
        .flat_map(|&z| {
            [-3.0f32, 0.0, 3.0, 6.0]
                .map(|x| ray(Vec3::new(x + 0.3, 0.1, z), Vec3::new(0.0, 0.0, -z.signum())))
        })
        .collect();
    let expected = [true, true, true, false, false, true, false, true];
    for traversal in TRAVERSALS {
        let hits: Vec<bool> = (cast(&scene, traversal, &rays).iter())
            .map(|h| h.t.is_finite())
            .collect();
        assert_eq!(
            hits, expected,
            "{traversal:?}: hits of rays from +z, then from -z"
        );
    }
}

/// An alpha-cut card (material 0, the checker texture) at z = 0 before a double-sided opaque
/// backdrop at z = -1: rays from z = 5 meet the card at t = 5, the backdrop at t = 6.
fn card_scene(card: Material) -> Scene {
    scene(
        vec![
            placed(0, Mat4::IDENTITY),
            placed(
                1,
                Mat4::from_translation(Vec3::new(0.0, 0.0, -1.0))
                    * Mat4::from_scale(Vec3::splat(3.0)),
            ),
        ],
        vec![card, white(Coverage::SOLID)],
    )
}

fn distance_class(h: &GpuProbeHit) -> &'static str {
    match h.t {
        t if (t - 5.0).abs() < 1e-3 => "card",
        t if (t - 6.0).abs() < 1e-3 => "backdrop",
        _ => "other",
    }
}

#[test]
fn a_mask_cuts_where_alpha_is_below_the_cutoff_and_the_ray_goes_on() {
    let mask = |alpha: f32, cutoff: f32| Coverage {
        alpha,
        mode: AlphaMode::Mask { cutoff },
        double_sided: true,
    };
    // A ray through each texel's centre: texel (i, j) spans x in [-1 + i/2, -1 + (i+1)/2]
    // and y from the top (uv (0, 0) at (-1, 1)).
    let centre = |i: usize, j: usize| {
        Vec3::new(
            -1.0 + 0.25 + 0.5 * i as f32,
            1.0 - 0.25 - 0.5 * j as f32,
            5.0,
        )
    };
    let rays: Vec<GpuProbeRay> = (0..16)
        .map(|k| ray(centre(k % 4, k / 4), Vec3::NEG_Z))
        .collect();
    for traversal in TRAVERSALS {
        // Cutoff 0.5: the opaque texels are there, the clear ones are not.
        let hits = cast(
            &card_scene(with_texture(white(mask(1.0, 0.5)))),
            traversal,
            &rays,
        );
        for (k, h) in hits.iter().enumerate() {
            let opaque = (k % 4 + k / 4) % 2 == 0;
            let want = if opaque { "card" } else { "backdrop" };
            assert_eq!(distance_class(h), want, "{traversal:?} texel {k}: {h:?}");
        }
        // The factor multiplies the texel: 0.4 × 1 is below the cutoff everywhere.
        let hits = cast(
            &card_scene(with_texture(white(mask(0.4, 0.5)))),
            traversal,
            &rays,
        );
        assert!(
            hits.iter().all(|h| distance_class(h) == "backdrop"),
            "{traversal:?}"
        );
        // OPAQUE ignores alpha, texture and factor alike.
        let opaque = Coverage {
            alpha: 0.1,
            ..Coverage::SOLID
        };
        let hits = cast(&card_scene(with_texture(white(opaque))), traversal, &rays);
        assert!(
            hits.iter().all(|h| distance_class(h) == "card"),
            "{traversal:?}"
        );
    }
}

#[test]
fn a_blended_surface_stops_a_share_of_rays_equal_to_its_alpha() {
    let alpha = 0.3;
    let blend = Coverage {
        alpha,
        mode: AlphaMode::Blend,
        double_sided: true,
    };
    let n = 4000;
    // Distinct rays over the card, each drawing its own number.
    let rays: Vec<GpuProbeRay> = (0..n)
        .map(|k| {
            let (x, y) = ((k % 64) as f32 / 64.0, (k / 64) as f32 / 64.0);
            ray(Vec3::new(1.8 * x - 0.9, 1.8 * y - 0.9, 5.0), Vec3::NEG_Z)
        })
        .collect();
    for traversal in TRAVERSALS {
        let hits = cast(&card_scene(white(blend)), traversal, &rays);
        let on_card = hits.iter().filter(|h| distance_class(h) == "card").count();
        let behind = hits
            .iter()
            .filter(|h| distance_class(h) == "backdrop")
            .count();
        assert_eq!(
            on_card + behind,
            n,
            "{traversal:?}: every ray meets one or the other"
        );
        let (share, alpha) = (on_card as f64 / n as f64, alpha as f64);
        let sigma = (alpha * (1.0 - alpha) / n as f64).sqrt();
        assert!(
            (share - alpha).abs() < 5.0 * sigma,
            "{traversal:?}: {share:.4} of the rays stopped at a card of alpha {alpha}"
        );
        // The same ray asks the same question twice and gets the same answer.
        assert_eq!(cast(&card_scene(white(blend)), traversal, &rays), hits);
    }
}

/// A white ground (y = 0) lit by a small spherical light above a horizontal 2 × 2 card at
/// y = 1; the camera looks down at the ground and the card's shadow.
fn shadow_scene(card: Mesh, card_material: Material, textures: Vec<Texture>) -> Scene {
    let horizontal = Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2);
    Scene {
        name: "card shadow".into(),
        meshes: vec![quad(), card],
        instances: vec![
            placed(0, horizontal * Mat4::from_scale(Vec3::splat(6.0))),
            Instance {
                mesh: 1,
                material: 1,
                transform: Mat4::from_translation(Vec3::Y) * horizontal,
            },
        ],
        boxes: vec![],
        spheres: vec![Sphere {
            center: Vec3::new(0.0, 3.0, 0.0),
            radius: 0.05,
            material: 2,
        }],
        materials: vec![
            white(Coverage::SOLID),
            card_material,
            Material::emitter(Vec3::ZERO, Vec3::splat(400.0)),
        ],
        textures,
        camera: Camera::look_at(Vec3::new(0.0, 6.0, 2.5), Vec3::ZERO, Vec3::Y, 34.0, 1.0),
        environment: Environment::black(),
        lights: Vec::new(),
        environment_map: None,
        light_selection: Default::default(),
    }
}

/// The checker's opaque squares as geometry: 8 quads of 0.5 × 0.5 in the card's plane.
fn checker_geometry() -> Mesh {
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    for j in 0..4 {
        for i in 0..4 {
            if (i + j) % 2 != 0 {
                continue;
            }
            let (x0, y1) = (-1.0 + 0.5 * i as f32, 1.0 - 0.5 * j as f32);
            let base = positions.len() as u32;
            positions.extend([
                Vec3::new(x0, y1 - 0.5, 0.0),
                Vec3::new(x0 + 0.5, y1 - 0.5, 0.0),
                Vec3::new(x0 + 0.5, y1, 0.0),
                Vec3::new(x0, y1, 0.0),
            ]);
            indices.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
        }
    }
    Mesh {
        name: "checker squares".into(),
        positions,
        indices,
        shading: VertexShading::default(),
    }
}

#[test]
fn an_alpha_cut_card_casts_the_shadow_of_the_same_shape_made_of_geometry() {
    let ctx = common::context();
    let cut = Coverage {
        alpha: 1.0,
        mode: AlphaMode::Mask { cutoff: 0.5 },
        double_sided: true,
    };
    let cut_out = shadow_scene(quad(), with_texture(white(cut)), vec![checker()]);
    let geometry = shadow_scene(checker_geometry(), white(Coverage::SOLID), vec![]);
    let (w, block) = (32usize, 8usize);
    for traversal in TRAVERSALS {
        let render = |scene: &Scene| {
            let mut renderer = Renderer::new(&ctx, scene).unwrap();
            renderer.set_traversal(traversal).unwrap();
            let s = common::settings(w as u32, w as u32, 64, 5, Integrator::Pt);
            let frame = regular_frame(&mut renderer, &scene.camera, &s).unwrap();
            assert_eq!(frame.stats.nonfinite_samples, 0);
            common::block_stats(&frame.rgb, w, block)
        };
        let (a, b) = (render(&cut_out), render(&geometry));
        common::assert_no_validation_messages(&ctx);
        // The shadow is there: the blocks differ by more than noise from one another.
        let means: Vec<f64> = a.iter().map(|blk| blk[0].0).collect();
        let (lo, hi) = means
            .iter()
            .fold((f64::MAX, 0.0f64), |(l, h), &m| (l.min(m), h.max(m)));
        assert!(
            hi > 2.0 * lo.max(1e-3),
            "{traversal:?}: no shadow to compare ({lo}..{hi})"
        );
        for (k, (x, y)) in a.iter().zip(&b).enumerate() {
            for c in 0..3 {
                let ((mx, ex), (my, ey)) = (x[c], y[c]);
                let se = (ex * ex + ey * ey).sqrt().max(1e-3 * mx.abs()).max(1e-6);
                let z = (mx - my).abs() / se;
                assert!(
                    z < 4.0,
                    "{traversal:?} block {k} channel {c}: cut-out {mx} vs geometry {my} (z = {z:.1})"
                );
            }
        }
    }
}
