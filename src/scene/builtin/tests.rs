use super::*;

const ASPECTS: [f32; 2] = [1.0, 16.0 / 9.0];

fn all(aspect: f32) -> Vec<Scene> {
    BUILTIN_SCENES
        .iter()
        .map(|(name, _)| builtin(name, aspect).unwrap_or_else(|e| panic!("{name}: {e}")))
        .collect()
}

/// World-space triangles of every instance, with the instance's material.
fn world_triangles(scene: &Scene) -> Vec<([Vec3; 3], u32)> {
    let mut out = Vec::new();
    for inst in &scene.instances {
        let mesh = &scene.meshes[inst.mesh as usize];
        for tri in &mesh.indices {
            let v = tri.map(|i| inst.transform.transform_point3(mesh.positions[i as usize]));
            out.push((v, inst.material));
        }
    }
    out
}

fn normal(v: &[Vec3; 3]) -> Vec3 {
    (v[1] - v[0]).cross(v[2] - v[0]).normalize()
}

/// World bounds of everything in the scene except `skip_boxes` leading boxes.
fn bounds(scene: &Scene, skip_boxes: usize) -> Option<(Vec3, Vec3)> {
    let mut points: Vec<Vec3> = world_triangles(scene)
        .iter()
        .flat_map(|(v, _)| *v)
        .collect();
    for b in scene.boxes.iter().skip(skip_boxes) {
        points.extend([b.min, b.max]);
    }
    for s in &scene.spheres {
        points.extend([
            s.center - Vec3::splat(s.radius),
            s.center + Vec3::splat(s.radius),
        ]);
    }
    let first = *points.first()?;
    Some(
        points
            .iter()
            .fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))),
    )
}

/// Camera-space tangent coordinates (x right, y up) and forward distance of a point.
fn project(camera: &Camera, p: Vec3) -> (f32, f32, f32) {
    let (r, u, f) = camera.basis();
    let d = p - camera.position;
    let z = d.dot(f);
    (d.dot(r) / z, d.dot(u) / z, z)
}

fn in_view(camera: &Camera, p: Vec3) -> bool {
    let (x, y, z) = project(camera, p);
    z > 0.0
        && (camera.angle_left.tan()..=camera.angle_right.tan()).contains(&x)
        && (camera.angle_down.tan()..=camera.angle_up.tan()).contains(&y)
}

#[test]
fn every_builtin_builds_with_its_own_name() {
    for aspect in ASPECTS {
        for (scene, (name, _)) in all(aspect).iter().zip(BUILTIN_SCENES) {
            assert_eq!(scene.name, *name);
        }
    }
}

#[test]
fn unknown_name_lists_the_known_ones() {
    match builtin("bunny", 1.0) {
        Err(SceneError::UnknownScene { name, known }) => {
            assert_eq!(name, "bunny");
            assert_eq!(
                known,
                "control, bunny-low, bunny-high, cubes-441, mirror-room, cornell"
            );
        }
        other => panic!("expected UnknownScene, got {other:?}"),
    }
}

#[test]
fn triangle_counts_match_the_thesis_and_mitsuba() {
    let counts: Vec<usize> = all(1.0).iter().map(Scene::triangle_count).collect();
    // control, bunny-low, bunny-high, cubes-441, mirror-room, cornell (6 rectangles × 2
    // + 2 cubes × 12).
    assert_eq!(counts, [0, 292, 4968, 0, 0, 36]);
}

#[test]
fn control_is_empty() {
    let s = control(1.0);
    assert!(s.meshes.is_empty() && s.instances.is_empty());
    assert!(s.boxes.is_empty() && s.spheres.is_empty());
    assert_eq!(s.environment, Environment::sky());
}

#[test]
fn cubes_441_has_441_irregular_cubes_on_the_ground() {
    let s = cubes_441(1.0);
    assert_eq!(s.boxes.len(), 442);
    let cubes = &s.boxes[1..];
    let mut edges = Vec::new();
    for b in cubes {
        let e = b.max - b.min;
        assert!(
            (e.x - e.y).abs() < 1e-5 && (e.x - e.z).abs() < 1e-5,
            "not a cube: {e}"
        );
        assert_eq!(b.min.y, 0.0, "cube does not rest on the ground");
        assert!((0.6..=1.2).contains(&e.x));
        edges.push(e.x);
    }
    let (lo, hi) = edges
        .iter()
        .fold((f32::MAX, f32::MIN), |(l, h), e| (l.min(*e), h.max(*e)));
    assert!(hi - lo > 0.4, "edges barely vary: {lo}..{hi}");
    // Neighbours never overlap: the largest edge is below the spacing.
    assert!(hi < CUBE_SPACING);
    // Several materials are used, glossy ones included.
    let glossy = cubes
        .iter()
        .filter(|b| s.materials[b.material as usize].is_specular())
        .count();
    assert!((40..=140).contains(&glossy), "{glossy} glossy cubes");
    let used: std::collections::BTreeSet<u32> = cubes.iter().map(|b| b.material).collect();
    assert_eq!(used.len(), 12);
}

#[test]
fn most_cubes_are_in_view() {
    for aspect in ASPECTS {
        let s = cubes_441(aspect);
        let visible = s.boxes[1..]
            .iter()
            .filter(|b| in_view(&s.camera, 0.5 * (b.min + b.max)))
            .count();
        assert!(
            visible >= 300,
            "aspect {aspect}: only {visible} cube centres in view"
        );
    }
}

#[test]
fn materials_are_the_theses_energy_conserving_and_finite() {
    for s in all(1.0) {
        for m in &s.materials {
            let m = m
                .thesis()
                .expect("built-in scenes keep the thesis' materials");
            let ok = |v: Vec3| v.is_finite() && v.min_element() >= 0.0;
            assert!(ok(m.kd) && ok(m.ks) && ok(m.emission), "{}: {m:?}", s.name);
            assert!((m.kd + m.ks).max_element() <= 1.0, "{}: {m:?}", s.name);
            assert!(m.alpha >= 0.0 && !m.alpha.is_nan(), "{}: {m:?}", s.name);
        }
    }
}

#[test]
fn every_material_index_is_in_range() {
    for s in all(1.0) {
        let n = s.materials.len() as u32;
        let used = s
            .instances
            .iter()
            .map(|i| i.material)
            .chain(s.boxes.iter().map(|b| b.material))
            .chain(s.spheres.iter().map(|sp| sp.material));
        for m in used {
            assert!(m < n, "{}: material {m} of {n}", s.name);
        }
        for i in &s.instances {
            assert!((i.mesh as usize) < s.meshes.len(), "{}", s.name);
        }
    }
}

#[test]
fn geometry_is_in_front_of_every_camera() {
    for aspect in ASPECTS {
        for s in all(aspect) {
            let Some((lo, hi)) = bounds(&s, 0) else {
                assert_eq!(s.name, "control");
                continue;
            };
            let centre = 0.5 * (lo + hi);
            assert!(
                in_view(&s.camera, centre),
                "{} aspect {aspect}: centre {centre} not in view",
                s.name
            );
        }
    }
}

#[test]
fn bunny_is_centred_and_fills_about_40_percent_of_the_height() {
    for name in ["bunny-low", "bunny-high"] {
        for aspect in ASPECTS {
            let s = builtin(name, aspect).unwrap();
            // Skip the ground box: the bunny alone.
            let (lo, hi) = bounds(&s, 1).unwrap();
            assert!(
                (hi.y - lo.y - 1.0).abs() < 0.02 && lo.y.abs() < 0.02,
                "{name}: {lo}..{hi}"
            );
            let c = &s.camera;
            let (x, y, _) = project(c, 0.5 * (lo + hi));
            let half_h = c.angle_up.tan();
            assert!(
                x.abs() < 0.15 * half_h && y.abs() < 0.15 * half_h,
                "{name}: off centre {x} {y}"
            );
            // Height on screen: the vertical span of the projected vertices.
            let (bottom, top) = world_triangles(&s)
                .iter()
                .flat_map(|(v, _)| *v)
                .map(|p| project(c, p).1)
                .fold((f32::MAX, f32::MIN), |(b, t), y| (b.min(y), t.max(y)));
            let fraction = (top - bottom) / (2.0 * half_h);
            assert!(
                (0.35..=0.45).contains(&fraction),
                "{name}: fills {fraction} of the height"
            );
            // Seen from above.
            assert!(c.forward.y < -0.1);
        }
    }
}

/// Slab test (Kay & Kajiya): entry distance of a ray into a box, if it hits in front.
fn hit_box(origin: Vec3, dir: Vec3, b: &AaBox) -> Option<f32> {
    let inv = dir.recip();
    let t0 = (b.min - origin) * inv;
    let t1 = (b.max - origin) * inv;
    let near = t0.min(t1).max_element();
    let far = t0.max(t1).min_element();
    (near <= far && far > 0.0).then_some(near.max(0.0))
}

#[test]
fn mirror_room_is_closed() {
    let s = mirror_room(1.0);
    let walls = &s.boxes[..6];
    let o = s.camera.position;
    assert!(
        o.cmpgt(ROOM_MIN).all() && o.cmplt(ROOM_MAX).all(),
        "camera outside the room"
    );
    for w in walls {
        let wall = s.materials[w.material as usize].thesis().unwrap();
        assert!(wall.alpha.is_infinite());
    }
    let mut state = 0x2545_f491_u64;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
    };
    for _ in 0..10_000 {
        // Uniform direction by rejection from the cube [−1, 1]³.
        let dir = loop {
            let d = Vec3::new(next(), next(), next());
            if (1e-3..=1.0).contains(&d.length_squared()) {
                break d.normalize();
            }
        };
        let t = walls
            .iter()
            .filter_map(|w| hit_box(o, dir, w))
            .fold(f32::INFINITY, f32::min);
        assert!(t < 20.0, "ray {dir} escapes the mirror room");
    }
}

#[test]
fn mirror_room_walls_overlap_at_every_edge() {
    // Every interior boundary point (corners included) lies inside some wall slab
    // pushed a hair outwards, so there is no gap between walls.
    let s = mirror_room(1.0);
    for k in 0..27 {
        let pick = |i: u32, lo: f32, hi: f32| [lo - 0.05, 0.5 * (lo + hi), hi + 0.05][i as usize];
        let p = Vec3::new(
            pick(k % 3, ROOM_MIN.x, ROOM_MAX.x),
            pick(k / 3 % 3, ROOM_MIN.y, ROOM_MAX.y),
            pick(k / 9, ROOM_MIN.z, ROOM_MAX.z),
        );
        if k == 13 {
            continue; // the room's centre
        }
        assert!(
            s.boxes[..6]
                .iter()
                .any(|b| p.cmpge(b.min).all() && p.cmple(b.max).all()),
            "gap at {p}"
        );
    }
}

#[test]
fn cornell_light_faces_down_and_walls_face_inwards() {
    let s = cornell(1.0);
    let tris = world_triangles(&s);
    let light: Vec<_> = tris
        .iter()
        .filter(|(_, m)| s.materials[*m as usize].is_emissive())
        .collect();
    assert_eq!(light.len(), 2);
    for (v, _) in &light {
        assert!(
            normal(v).abs_diff_eq(Vec3::NEG_Y, 1e-5),
            "light normal {}",
            normal(v)
        );
        // Just below the ceiling, 0.46 × 0.38.
        assert!(v.iter().all(|p| (p.y - 0.99).abs() < 1e-5));
    }
    let area: f32 = light
        .iter()
        .map(|(v, _)| 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length())
        .sum();
    assert!((area - 0.46 * 0.38).abs() < 1e-5, "light area {area}");
    // The five walls (instances 1..6): each triangle's normal points to the box centre.
    for inst in &s.instances[1..6] {
        let c = inst.transform.transform_point3(Vec3::ZERO);
        let n = inst.transform.transform_vector3(Vec3::Z).normalize();
        assert!(n.dot(-c) > 0.99, "wall at {c} faces {n}");
    }
    for (v, _) in &tris[2..12] {
        let centroid = (v[0] + v[1] + v[2]) / 3.0;
        assert!(normal(v).dot(-centroid) > 0.99);
    }
}

#[test]
fn cornell_boxes_have_outward_faces_and_sit_on_the_floor() {
    let s = cornell(1.0);
    for inst in &s.instances[6..] {
        let mesh = &s.meshes[inst.mesh as usize];
        assert_eq!(mesh.indices.len(), 12);
        let centre = inst.transform.transform_point3(Vec3::ZERO);
        let mut min_y = f32::MAX;
        for tri in &mesh.indices {
            let v = tri.map(|i| inst.transform.transform_point3(mesh.positions[i as usize]));
            let centroid = (v[0] + v[1] + v[2]) / 3.0;
            assert!(normal(&v).dot(centroid - centre) > 0.0, "inward face");
            min_y = v.iter().fold(min_y, |m, p| m.min(p.y));
        }
        // Both boxes rest on the floor (y = −1) up to Mitsuba's rounding (0.61 vs 0.6).
        assert!((min_y + 1.0).abs() < 0.015, "box bottom at {min_y}");
    }
}

#[test]
fn cornell_fov_follows_mitsubas_smaller_axis() {
    let half = (39.3077f32 / 2.0).to_radians();
    let wide = cornell(16.0 / 9.0).camera;
    assert!((wide.angle_up - half).abs() < 1e-6);
    let square = cornell(1.0).camera;
    assert!((square.angle_up - half).abs() < 1e-6 && (square.angle_right - half).abs() < 1e-6);
    let tall = cornell(0.5).camera;
    assert!((tall.angle_right - half).abs() < 1e-6);
    assert!(tall.angle_up > half);
    assert_eq!(square.position, Vec3::new(0.0, 0.0, 3.9));
    assert!(square.forward.abs_diff_eq(Vec3::NEG_Z, 1e-6));
}
