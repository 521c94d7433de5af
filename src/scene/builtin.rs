//! The built-in scenes: the five evaluation scenes of the thesis (§3.1.1: control, two bunnies,
//! 441 cubes, mirror room) plus Mitsuba 3's `mi.cornell_box()`, rebuilt number for number so
//! our images can be compared with a Mitsuba render.
//!
//! Every scene is a pure function of the image aspect ratio (`width / height`); cameras keep
//! their vertical field of view (except `cornell`, which follows Mitsuba's `fov_axis`).

use glam::{Mat4, Vec3};

use super::{AaBox, Camera, Environment, Instance, Material, Mesh, Scene, SceneError, Sphere};

/// Name and one-line description of every built-in scene, in the order `fovea scenes` lists them.
pub const BUILTIN_SCENES: &[(&str, &str)] = &[
    (
        "control",
        "background only, no geometry: the frame cost without any latency factor",
    ),
    (
        "bunny-low",
        "a 292-triangle bunny on an analytic ground: triangle intersection cost",
    ),
    (
        "bunny-high",
        "a 4968-triangle bunny on an analytic ground: triangle intersection cost",
    ),
    (
        "cubes-441",
        "441 axis-aligned cubes on a 21×21 grid: many separate objects",
    ),
    (
        "mirror-room",
        "a closed room of slightly emissive mirrors: every path reaches the bounce limit",
    ),
    (
        "cornell",
        "Mitsuba 3's mi.cornell_box(), number for number: comparison with Mitsuba",
    ),
];

/// Builds the built-in scene `name` for an image of aspect ratio `aspect` (width / height).
pub fn builtin(name: &str, aspect: f32) -> Result<Scene, SceneError> {
    match name {
        "control" => Ok(control(aspect)),
        "bunny-low" => bunny_low(aspect),
        "bunny-high" => bunny_high(aspect),
        "cubes-441" => Ok(cubes_441(aspect)),
        "mirror-room" => Ok(mirror_room(aspect)),
        "cornell" => Ok(cornell(aspect)),
        _ => Err(SceneError::UnknownScene {
            name: name.to_owned(),
            known: BUILTIN_SCENES
                .iter()
                .map(|(n, _)| *n)
                .collect::<Vec<_>>()
                .join(", "),
        }),
    }
}

/// Vertical field of view of the thesis-style scenes, a typical desktop view.
const FOV_Y_DEG: f32 = 60.0;

/// The thesis' control scene: nothing but the sky, so the frame time measures the pipeline
/// itself (ray generation, interpolation, merging) without any latency factor.
pub fn control(aspect: f32) -> Scene {
    let eye = Vec3::new(0.0, 1.6, 0.0);
    Scene {
        name: "control".into(),
        meshes: Vec::new(),
        instances: Vec::new(),
        boxes: Vec::new(),
        spheres: Vec::new(),
        materials: Vec::new(),
        textures: Vec::new(),
        camera: Camera::look_at(eye, eye + Vec3::NEG_Z, Vec3::Y, FOV_Y_DEG, aspect),
        environment: Environment::sky(),
        lights: Vec::new(),
        environment_map: None,
        light_selection: Default::default(),
    }
}

/// The thesis' first triangle-intersection scene (fig. 3.1): a 292-triangle bunny, so the
/// frame time measures the cost of triangle intersections. The ground is an analytic box, so
/// `triangle_count()` is exactly the bunny's.
pub fn bunny_low(aspect: f32) -> Result<Scene, SceneError> {
    let mesh = super::gltf_load::mesh_from_glb_bytes(
        include_bytes!("../../assets/bunny-low.glb"),
        "bunny-low.glb",
    )?;
    Ok(bunny_scene("bunny-low", mesh, aspect))
}

/// The thesis' second triangle-intersection scene (fig. 3.2): the same view as `bunny-low`
/// with a 4968-triangle bunny, to see how the cost grows with the triangle count.
pub fn bunny_high(aspect: f32) -> Result<Scene, SceneError> {
    let mesh = super::gltf_load::mesh_from_glb_bytes(
        include_bytes!("../../assets/bunny-high.glb"),
        "bunny-high.glb",
    )?;
    Ok(bunny_scene("bunny-high", mesh, aspect))
}

/// Field of view of the bunny scenes: narrow enough that the bunny fills ~40% of the height.
const BUNNY_FOV_Y_DEG: f32 = 45.0;

/// A bunny (asset: unit height, feet at y = 0, centred on x = z = 0) placed as is on a large
/// grey ground box, seen slightly from above (15°) from a distance at which its height is
/// ~40% of the image height (1 / (2 · 3.3 · tan 22.5°) ≈ 0.37 at the target's depth; its
/// nearer parts make it ~0.41 on screen).
fn bunny_scene(name: &str, mesh: Mesh, aspect: f32) -> Scene {
    let target = Vec3::new(0.0, 0.45, 0.0);
    let distance = 3.3;
    let elevation = 15f32.to_radians();
    let eye = target + distance * Vec3::new(0.0, elevation.sin(), elevation.cos());
    Scene {
        name: name.into(),
        meshes: vec![mesh],
        instances: vec![Instance {
            mesh: 0,
            material: 1,
            transform: Mat4::IDENTITY,
        }],
        boxes: vec![ground_box(0)],
        spheres: Vec::new(),
        materials: vec![
            Material::diffuse(Vec3::splat(0.5)),
            Material::phong(
                Vec3::new(0.75, 0.62, 0.58),
                Vec3::splat(0.1),
                40.0,
                Vec3::ZERO,
            ),
        ],
        textures: Vec::new(),
        camera: Camera::look_at(eye, target, Vec3::Y, BUNNY_FOV_Y_DEG, aspect),
        environment: Environment::sky(),
        lights: Vec::new(),
        environment_map: None,
        light_selection: Default::default(),
    }
}

/// A 100 m × 100 m ground slab whose top face is y = 0 (analytic, so it adds no triangles).
fn ground_box(material: u32) -> AaBox {
    AaBox {
        min: Vec3::new(-50.0, -0.1, -50.0),
        max: Vec3::new(50.0, 0.0, 50.0),
        material,
    }
}

/// Cubes per side of the `cubes-441` grid (21² = 441, the thesis' count).
const CUBES_PER_SIDE: u32 = 21;
/// Centre-to-centre distance of the grid, so neighbouring cubes (edge ≤ 1.2) never touch.
const CUBE_SPACING: f32 = 1.5;

/// The thesis' multi-object scene (fig. 3.3): 441 axis-aligned cubes, so the frame time
/// measures the cost of many separate objects rather than of triangles.
///
/// `boxes[0]` is the ground slab and `boxes[1..=441]` are the cubes (`boxes.len() == 442`),
/// row by row along x then z. Each cube rests on the ground; its edge (0.6–1.2) and its colour
/// (a six-colour palette, one in five with a Phong highlight) come from a hash of its index,
/// so the grid is irregular but the same on every run.
pub fn cubes_441(aspect: f32) -> Scene {
    let palette = [
        Vec3::new(0.80, 0.25, 0.20),
        Vec3::new(0.20, 0.55, 0.80),
        Vec3::new(0.85, 0.75, 0.25),
        Vec3::new(0.30, 0.70, 0.35),
        Vec3::new(0.75, 0.75, 0.75),
        Vec3::new(0.55, 0.30, 0.70),
    ];
    // Materials: 0 ground, then per colour a diffuse and a glossy variant (kd scaled to keep
    // kd + ks ≤ 1).
    let mut materials = vec![Material::diffuse(Vec3::splat(0.5))];
    for colour in palette {
        materials.push(Material::diffuse(colour));
        materials.push(Material::phong(
            0.7 * colour,
            Vec3::splat(0.25),
            60.0,
            Vec3::ZERO,
        ));
    }

    let half = (CUBES_PER_SIDE - 1) as f32 * 0.5;
    let mut boxes = vec![ground_box(0)];
    for i in 0..CUBES_PER_SIDE * CUBES_PER_SIDE {
        let h = hash_u32(i);
        let (col, row) = (i % CUBES_PER_SIDE, i / CUBES_PER_SIDE);
        let centre = Vec3::new(col as f32 - half, 0.0, row as f32 - half) * CUBE_SPACING;
        let edge = 0.6 + 0.6 * ((h & 0xffff) as f32 / 65535.0);
        let colour = (h >> 16) % palette.len() as u32;
        let glossy = u32::from((h >> 24).is_multiple_of(5));
        let half_xz = Vec3::new(0.5 * edge, 0.0, 0.5 * edge);
        boxes.push(AaBox {
            min: centre - half_xz,
            max: centre + half_xz + Vec3::new(0.0, edge, 0.0),
            material: 1 + 2 * colour + glossy,
        });
    }

    // From a raised corner, looking across the diagonal of the grid to a point just past
    // its centre, so the near cubes and the rows behind them are both in view.
    let eye = Vec3::new(-17.0, 9.0, 17.0);
    let target = Vec3::new(1.0, 0.0, -1.0);
    Scene {
        name: "cubes-441".into(),
        meshes: Vec::new(),
        instances: Vec::new(),
        boxes,
        spheres: Vec::new(),
        materials,
        textures: Vec::new(),
        camera: Camera::look_at(eye, target, Vec3::Y, FOV_Y_DEG, aspect),
        environment: Environment::sky(),
        lights: Vec::new(),
        environment_map: None,
        light_selection: Default::default(),
    }
}

/// Thomas Wang's 32-bit integer hash: turns an index into well-mixed bits.
fn hash_u32(mut x: u32) -> u32 {
    x = (x ^ 61) ^ (x >> 16);
    x = x.wrapping_mul(9);
    x ^= x >> 4;
    x = x.wrapping_mul(0x27d4_eb2d);
    x ^ (x >> 15)
}

/// Interior of the mirror room: 6 m × 3 m × 6 m, floor at y = 0.
const ROOM_MIN: Vec3 = Vec3::new(-3.0, 0.0, -3.0);
const ROOM_MAX: Vec3 = Vec3::new(3.0, 3.0, 3.0);
/// Wall thickness; every slab is extended by this much on all sides so the six overlap at
/// the edges and corners and no ray can slip out between two of them.
const WALL: f32 = 0.1;

/// The thesis' reflection scene (fig. 3.4): a closed room whose six walls are perfect mirrors
/// (k_s 0.9) that also glow slightly (0.05), "to reduce the effect of rays losing energy" and
/// to light the room. No ray can leave, so every path runs to the bounce limit: the frame
/// time measures the worst case of reflections.
///
/// `boxes[0..6]` are the walls (floor, ceiling, −x, +x, −z, +z), `boxes[6]` a diffuse block;
/// two spheres (diffuse, glossy) give the reflections something to show.
pub fn mirror_room(aspect: f32) -> Scene {
    let (lo, hi) = (ROOM_MIN - Vec3::splat(WALL), ROOM_MAX + Vec3::splat(WALL));
    let slab = |min: Vec3, max: Vec3| AaBox {
        min,
        max,
        material: 0,
    };
    let boxes = vec![
        slab(lo, Vec3::new(hi.x, ROOM_MIN.y, hi.z)),
        slab(Vec3::new(lo.x, ROOM_MAX.y, lo.z), hi),
        slab(lo, Vec3::new(ROOM_MIN.x, hi.y, hi.z)),
        slab(Vec3::new(ROOM_MAX.x, lo.y, lo.z), hi),
        slab(lo, Vec3::new(hi.x, hi.y, ROOM_MIN.z)),
        slab(Vec3::new(lo.x, lo.y, ROOM_MAX.z), hi),
        AaBox {
            min: Vec3::new(-0.2, 0.0, -2.6),
            max: Vec3::new(0.6, 0.8, -1.8),
            material: 3,
        },
    ];
    let materials = vec![
        Material::phong(
            Vec3::ZERO,
            Vec3::splat(0.9),
            f32::INFINITY,
            Vec3::splat(0.05),
        ),
        Material::diffuse(Vec3::new(0.8, 0.3, 0.2)),
        Material::phong(
            Vec3::new(0.1, 0.2, 0.4),
            Vec3::splat(0.6),
            200.0,
            Vec3::ZERO,
        ),
        Material::diffuse(Vec3::new(0.3, 0.6, 0.3)),
    ];
    let spheres = vec![
        Sphere {
            center: Vec3::new(-1.1, 0.6, -1.0),
            radius: 0.6,
            material: 1,
        },
        Sphere {
            center: Vec3::new(1.0, 0.5, -0.2),
            radius: 0.5,
            material: 2,
        },
    ];
    let eye = Vec3::new(0.0, 1.6, 2.4);
    let target = Vec3::new(0.0, 1.0, -3.0);
    Scene {
        name: "mirror-room".into(),
        meshes: Vec::new(),
        instances: Vec::new(),
        boxes,
        spheres,
        materials,
        textures: Vec::new(),
        camera: Camera::look_at(eye, target, Vec3::Y, FOV_Y_DEG, aspect),
        environment: Environment::black(),
        lights: Vec::new(),
        environment_map: None,
        light_selection: Default::default(),
    }
}

/// Mitsuba 3's `mi.cornell_box()` (mitsuba3 `src/python/python/util.py`), number for number,
/// so an image of ours can be compared with a Mitsuba render of the same scene.
///
/// Shapes are Mitsuba's: `rectangle` = the quad z = 0, x, y ∈ [−1, 1], normal +Z (2 triangles,
/// Mitsuba's own vertex order); `cube` = [−1, 1]³ with outward normals (12 triangles). Each is
/// placed by an instance whose matrix is Mitsuba's `to_world`, `translate · rotate · scale`
/// (rotations in degrees about the given axis, right-handed). 6 rectangles + 2 cubes make
/// 36 triangles. All surfaces are Lambertian; the light is one-sided and faces −Y.
///
/// Camera: `look_at([0, 0, 3.9], [0, 0, 0], [0, 1, 0])`, `fov 39.3077`, `fov_axis 'smaller'`:
/// the field of view spans the image height when `aspect > 1`, else its width. Mitsuba's
/// integrator there is `path` with `max_depth 8`; the environment is black (no emitter but
/// the light).
pub fn cornell(aspect: f32) -> Scene {
    const FOV_DEG: f32 = 39.3077;
    let white = Vec3::new(0.885809, 0.698859, 0.666422);
    let green = Vec3::new(0.105421, 0.37798, 0.076425);
    let red = Vec3::new(0.570068, 0.0430135, 0.0443706);
    let radiance = Vec3::new(18.387, 13.9873, 6.75357);
    let materials = vec![
        Material::diffuse(white),
        Material::diffuse(green),
        Material::diffuse(red),
        Material::emitter(white, radiance),
    ];
    let (rectangle, cube) = (0, 1);
    let (m_white, m_green, m_red, m_light) = (0, 1, 2, 3);

    let to_world = |t: [f32; 3], axis: Vec3, deg: f32, s: Vec3| {
        Mat4::from_translation(Vec3::from(t))
            * Mat4::from_axis_angle(axis, deg.to_radians())
            * Mat4::from_scale(s)
    };
    let place = |mesh, material, transform| Instance {
        mesh,
        material,
        transform,
    };
    let instances = vec![
        place(
            rectangle,
            m_light,
            to_world(
                [0.0, 0.99, 0.01],
                Vec3::X,
                90.0,
                Vec3::new(0.23, 0.19, 0.19),
            ),
        ),
        place(
            rectangle,
            m_white,
            to_world([0.0, -1.0, 0.0], Vec3::X, -90.0, Vec3::ONE),
        ),
        place(
            rectangle,
            m_white,
            to_world([0.0, 1.0, 0.0], Vec3::X, 90.0, Vec3::ONE),
        ),
        place(
            rectangle,
            m_white,
            to_world([0.0, 0.0, -1.0], Vec3::X, 0.0, Vec3::ONE),
        ),
        place(
            rectangle,
            m_green,
            to_world([1.0, 0.0, 0.0], Vec3::Y, -90.0, Vec3::ONE),
        ),
        place(
            rectangle,
            m_red,
            to_world([-1.0, 0.0, 0.0], Vec3::Y, 90.0, Vec3::ONE),
        ),
        place(
            cube,
            m_white,
            to_world([0.335, -0.7, 0.38], Vec3::Y, -17.0, Vec3::splat(0.3)),
        ),
        place(
            cube,
            m_white,
            to_world(
                [-0.33, -0.4, -0.28],
                Vec3::Y,
                18.25,
                Vec3::new(0.3, 0.61, 0.3),
            ),
        ),
    ];

    // fov_axis 'smaller' (Mitsuba's sensor.cpp: `aspect > 1 ? "y" : "x"`): convert a
    // horizontal field of view to the vertical one `Camera::look_at` takes.
    let fov_y_deg = if aspect > 1.0 {
        FOV_DEG
    } else {
        2.0 * ((0.5 * FOV_DEG.to_radians()).tan() / aspect)
            .atan()
            .to_degrees()
    };
    Scene {
        name: "cornell".into(),
        meshes: vec![mitsuba_rectangle(), mitsuba_cube()],
        instances,
        boxes: Vec::new(),
        spheres: Vec::new(),
        materials,
        textures: Vec::new(),
        camera: Camera::look_at(
            Vec3::new(0.0, 0.0, 3.9),
            Vec3::ZERO,
            Vec3::Y,
            fov_y_deg,
            aspect,
        ),
        environment: Environment::black(),
        lights: Vec::new(),
        environment_map: None,
        light_selection: Default::default(),
    }
}

/// Mitsuba's `rectangle`: vertices and faces as in its `rectangle.cpp` (faces {1,2,0},
/// {1,3,2}), counter-clockwise seen from +Z.
fn mitsuba_rectangle() -> Mesh {
    Mesh {
        name: "rectangle".into(),
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        ],
        indices: vec![[1, 2, 0], [1, 3, 2]],
        shading: Default::default(),
    }
}

/// Mitsuba's `cube`, [−1, 1]³: corner `c` is at (±1, ±1, ±1) with bit k of `c` choosing the
/// sign of axis k (as in its `cube.cpp`); each face is two triangles, counter-clockwise seen
/// from outside.
fn mitsuba_cube() -> Mesh {
    let positions = (0..8u32)
        .map(|c| {
            let s = |bit: u32| if c & bit != 0 { 1.0 } else { -1.0 };
            Vec3::new(s(1), s(2), s(4))
        })
        .collect();
    // Quads counter-clockwise from outside: −x, +x, −y, +y, −z, +z.
    let quads: [[u32; 4]; 6] = [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ];
    let indices = quads
        .iter()
        .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
        .collect();
    Mesh {
        name: "cube".into(),
        positions,
        indices,
        shading: Default::default(),
    }
}

#[cfg(test)]
mod tests;
