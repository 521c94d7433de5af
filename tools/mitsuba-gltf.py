#!/usr/bin/env python3
"""Mitsuba 3 as the reference for glTF scenes fovea's glb writer wrote: same geometry, camera,
textures and BRDF, compared with fovea's render block by block.

A peer tool, never a dependency of fovea (install as tools/mitsuba-cornell.py says: mitsuba
3.9.0 with drjit 1.4.0 in a venv). It reads what src/scene/glb_write/ writes (flat nodes with
matrices, one primitive per mesh, POSITION/NORMAL/TEXCOORD_0 and u32 indices, PNG images, a
camera node, KHR_lights_punctual nodes) -- e.g. assets/gltf/textured-room.glb or
punctual-lights.glb -- and builds the Mitsuba scene from it:

- meshes as PLY files (world-space positions, glTF's uv as stored: both renderers put uv (0, 0)
  at the image's first texel);
- glTF's metallic-roughness BRDF (the specification's Appendix B, as glsl/gltf_brdf.glsl has
  it: GGX with alpha = roughness^2, height-correlated Smith visibility, Schlick Fresnel with
  F0 = mix(0.04, base, metallic), a Lambertian base(1 - metallic) weighted by 1 - F) as a
  Python BSDF,
  sampled by a cosine lobe (unbiased; slow only for glossy surfaces, so keep the compared
  scenes rough), base colour textures as Mitsuba `bitmap`s (sRGB, nearest or bilinear as the
  glTF sampler says, no mipmaps: compare scenes whose textures are read at level 0);
- emission (emissiveFactor x KHR_materials_emissive_strength) as a one-sided area emitter;
- KHR_lights_punctual lights (node translation + rotation, shining along the node's -Z), in
  fovea's units (src/scene/lights.rs: glTF's colour x intensity taken one for one): a point
  light as Mitsuba's `point`, a directional light as `directional`, and a spot or a light with
  a `range` as the Python emitter `gltf_punctual` below, which has the extension's falloffs
  (Mitsuba's `spot` falls off linearly in angle, and no built-in light has a range window);
- the environment: with --env FILE (.exr or .hdr) [--env-rotate DEG], fovea is given the same
  flags and Mitsuba an `envmap` resampled and turned so that both read the same radiance in
  every direction (mitsuba_env); without --env, fovea is given an all-black environment (it
  would otherwise light a .glb with its gradient sky, which Mitsuba does not model) and
  Mitsuba none, so lights and emission are compared alone;
- shading normals (NORMAL, interpolated) where the primitive has them, as fovea shades;
- the perspective camera; the `path` integrator with max_depth = fovea's --max-bounces + 1.

Each renderer renders the scene twice with different seeds; the noise of a block's mean is
estimated from the two renders' difference, so texture edges inside a block do not count as
noise. Prints the worst block z-score per channel and exits 1 if any block differs by more
than --z-limit standard errors.

Usage: python tools/mitsuba-gltf.py SCENE.glb --fovea target/release/fovea [--size 64]
       [--spp 256] [--block 8] [--max-bounces 8] [--z-limit 4.5] [--out DIR]
       [--env FILE.exr [--env-rotate DEG]]
"""
import argparse, json, math, os, struct, subprocess, sys, tempfile

import drjit as dr
import mitsuba as mi
import numpy as np

mi.set_variant('llvm_ad_rgb')


def read_glb(path):
    data = open(path, 'rb').read()
    magic, version, _ = struct.unpack_from('<4sII', data, 0)
    if magic != b'glTF' or version != 2:
        sys.exit(f'{path}: not a glTF 2.0 binary')
    json_len, = struct.unpack_from('<I', data, 12)
    doc = json.loads(data[20:20 + json_len])
    bin_at = 20 + json_len
    bin_len, = struct.unpack_from('<I', data, bin_at)
    return doc, data[bin_at + 8:bin_at + 8 + bin_len]


def accessor(doc, binary, index):
    a = doc['accessors'][index]
    view = doc['bufferViews'][a['bufferView']]
    width = {'SCALAR': 1, 'VEC2': 2, 'VEC3': 3, 'VEC4': 4}[a['type']]
    dtype = {5126: np.float32, 5125: np.uint32}[a['componentType']]
    start = view.get('byteOffset', 0) + a.get('byteOffset', 0)
    flat = np.frombuffer(binary, dtype=dtype, count=a['count'] * width, offset=start)
    return flat.reshape(a['count'], width)


def write_ply(path, positions, uv, faces, normals=None):
    with open(path, 'wb') as f:
        f.write(b'ply\nformat binary_little_endian 1.0\n')
        f.write(f'element vertex {len(positions)}\n'.encode())
        f.write(b'property float x\nproperty float y\nproperty float z\n')
        if normals is not None:
            f.write(b'property float nx\nproperty float ny\nproperty float nz\n')
        f.write(b'property float u\nproperty float v\n')
        f.write(f'element face {len(faces)}\n'.encode())
        f.write(b'property list uchar uint vertex_indices\nend_header\n')
        columns = [positions] + ([normals] if normals is not None else []) + [uv]
        vertices = np.hstack(columns).astype('<f4')
        f.write(vertices.tobytes())
        tris = np.empty(len(faces), dtype=[('n', 'u1'), ('i', '<u4', 3)])
        tris['n'] = 3
        tris['i'] = faces
        f.write(tris.tobytes())


def quaternion_matrix(q):
    """The rotation of glTF's unit quaternion [x, y, z, w]."""
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def node_matrix(node):
    """The node's 4x4 transform: its `matrix` (column-major) or translation x rotation x scale.
    The writer's nodes are flat (no children), so this is the world transform."""
    if 'matrix' in node:
        return np.array(node['matrix'], dtype=np.float64).reshape(4, 4).T
    q = np.array(node.get('rotation', [0, 0, 0, 1]), dtype=np.float64)
    m = np.eye(4)
    m[:3, :3] = quaternion_matrix(q / np.linalg.norm(q)) * np.array(node.get('scale', [1, 1, 1]))
    m[:3, 3] = node.get('translation', [0, 0, 0])
    return m


class GltfBrdf(mi.BSDF):
    """glTF 2.0's metallic-roughness BRDF, shaded on whichever side the ray arrives (fovea shades
    both faces of a double-sided surface)."""

    def __init__(self, props):
        mi.BSDF.__init__(self, props)
        base = props['base_color']
        # A texture (bitmap) is evaluated at the hit; a plain colour arrives as a colour.
        self.base = base if hasattr(base, 'eval') else None
        self.base_value = None if self.base is not None else mi.Color3f(base)
        self.metallic = props['metallic']
        self.alpha = max(props['roughness'] ** 2, 1e-4)
        flags = mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide
        self.m_components = [flags]
        self.m_flags = flags

    def brdf(self, si, wo, active):
        wi = mi.Vector3f(si.wi)
        flip = wi.z < 0
        wi.z = dr.select(flip, -wi.z, wi.z)
        wo = mi.Vector3f(wo.x, wo.y, dr.select(flip, -wo.z, wo.z))
        n_v, n_l = wi.z, wo.z
        valid = active & (n_v > 0) & (n_l > 0)
        h = dr.normalize(wi + wo)
        n_h, v_h = h.z, dr.abs(dr.dot(wi, h))
        a2 = self.alpha * self.alpha
        d = a2 / (dr.pi * dr.square(n_h * n_h * (a2 - 1) + 1))
        vis = 0.5 / (n_l * dr.sqrt(n_v * n_v * (1 - a2) + a2) + n_v * dr.sqrt(n_l * n_l * (1 - a2) + a2))
        base = self.base.eval(si, active) if self.base is not None else self.base_value
        schlick = dr.power(1 - v_h, 5)
        f0 = dr.lerp(mi.Color3f(0.04), base, self.metallic)
        f = f0 + (1 - f0) * schlick
        # The base is weighted by 1 - F with F0 = mix(0.04, base, metallic), as
        # glsl/gltf_brdf.glsl and the glTF specification's sample implementation have it (its
        # mix(dielectric, metal, metallic) form weighs it by the dielectric's 1 - F instead;
        # the two differ only for 0 < metallic < 1).
        diffuse = (1 - f) * (1 - self.metallic) * base / dr.pi
        value = diffuse + f * d * vis
        return dr.select(valid, value, 0.0), n_l

    def sample(self, ctx, si, sample1, sample2, active):
        local = mi.warp.square_to_cosine_hemisphere(sample2)
        wo = mi.Vector3f(local.x, local.y, dr.select(si.wi.z < 0, -local.z, local.z))
        bs = mi.BSDFSample3f()
        bs.wo = wo
        bs.pdf = mi.warp.square_to_cosine_hemisphere_pdf(local)
        bs.eta = 1.0
        bs.sampled_type = mi.UInt32(+mi.BSDFFlags.DiffuseReflection)
        bs.sampled_component = mi.UInt32(0)
        value, cos_o = self.brdf(si, wo, active)
        weight = dr.select(bs.pdf > 0, value * cos_o / bs.pdf, 0.0)
        return bs, weight

    def eval(self, ctx, si, wo, active):
        value, cos_o = self.brdf(si, wo, active)
        return value * cos_o

    def pdf(self, ctx, si, wo, active):
        same_side = si.wi.z * wo.z > 0
        return dr.select(same_side, mi.warp.square_to_cosine_hemisphere_pdf(mi.Vector3f(wo.x, wo.y, dr.abs(wo.z))), 0.0)

    def eval_pdf(self, ctx, si, wo, active):
        return self.eval(ctx, si, wo, active), self.pdf(ctx, si, wo, active)

    def to_string(self):
        return 'GltfBrdf'


mi.register_bsdf('gltf_brdf', lambda props: GltfBrdf(props))


class GltfPunctual(mi.Emitter):
    """A KHR_lights_punctual point or spot light with the extension's falloffs, as fovea has them
    (glsl/lights.glsl, punctual_arrival): radiant intensity I (glTF colour x intensity in
    candela, taken as fovea's radiance x m^2 one for one), so the irradiance on a surface facing
    the light at distance d is

        I / d^2 * clamp(1 - (d / range)^4, 0, 1) * clamp(cos(theta) * scale + offset, 0, 1)^2

    with the range window only where the light has a range (0 here: it has none), theta the angle
    from the spot's axis, scale = 1 / max(1e-3, cos(inner) - cos(outer)) and
    offset = -cos(outer) * scale (a point light: scale 0, offset 1). A delta in position: only
    next-event estimation finds it, so it has no pdf or radiance for a direction (eval,
    pdf_direction: 0)."""

    def __init__(self, props):
        mi.Emitter.__init__(self, props)
        self.position = mi.Point3f(props['position'])
        self.axis = dr.normalize(mi.Vector3f(props['direction']))
        self.intensity = mi.Color3f(props['intensity'])
        self.range = props['range']
        self.scale = props['scale']
        self.offset = props['offset']
        self.m_flags = mi.EmitterFlags.DeltaPosition

    def falloff(self, d, dist):
        """The factor of I at distance dist along the unit direction d from the light (cone
        and range window, without the inverse square)."""
        cone = dr.clip(dr.dot(self.axis, d) * self.scale + self.offset, 0.0, 1.0)
        if self.range <= 0:
            return cone * cone
        window = dr.clip(1 - dr.square(dr.square(dist / self.range)), 0.0, 1.0)
        return cone * cone * window

    def sample_direction(self, it, sample, active):
        ds = dr.zeros(mi.DirectionSample3f)
        ds.p = mi.Point3f(self.position)
        ds.n = mi.Normal3f(0.0)
        ds.time = it.time
        ds.pdf = 1.0  # a delta: the path integrator gives it MIS weight 1
        ds.delta = True
        ds.emitter = mi.EmitterPtr(self)
        to_light = ds.p - it.p
        dist2 = dr.maximum(dr.squared_norm(to_light), 1e-30)
        ds.dist = dr.sqrt(dist2)
        ds.d = to_light / ds.dist
        # The returned weight is radiance / pdf: here the irradiance facing the light.
        weight = self.intensity * (self.falloff(-ds.d, ds.dist) / dist2)
        return ds, dr.select(active, weight, 0.0)

    def pdf_direction(self, it, ds, active):
        return mi.Float(0.0)

    def eval(self, si, active):
        return mi.Color3f(0.0)

    def sample_ray(self, time, sample1, sample2, sample3, active):
        # Light tracing only (the path integrator never calls it): a direction uniform over the
        # sphere, weighted by the intensity that way over its density 1 / 4 pi (no range window:
        # it depends on where the ray ends).
        d = mi.warp.square_to_uniform_sphere(sample3)
        ray = mi.Ray3f(mi.Point3f(self.position), d, time)
        return ray, self.intensity * (4 * dr.pi * self.falloff(d, 0.0))

    def traverse(self, callback):
        callback.put('intensity', self.intensity, mi.ParamFlags.NonDifferentiable)

    def to_string(self):
        return 'GltfPunctual'


mi.register_emitter('gltf_punctual', lambda props: GltfPunctual(props))


def texture_dict(doc, binary, info, folder):
    tex = doc['textures'][info['index']]
    image = doc['images'][tex['source']]
    view = doc['bufferViews'][image['bufferView']]
    at = view.get('byteOffset', 0)
    path = os.path.join(folder, f"texture{info['index']}.png")
    open(path, 'wb').write(binary[at:at + view['byteLength']])
    sampler = doc['samplers'][tex['sampler']] if 'sampler' in tex else {}
    if sampler.get('minFilter', 9729) not in (9728, 9729):
        print(f"warning: texture {info['index']} uses mipmaps; Mitsuba reads level 0 only", file=sys.stderr)
    nearest = sampler.get('magFilter', 9729) == 9728
    return {'type': 'bitmap', 'filename': path, 'raw': False,
            'filter_type': 'nearest' if nearest else 'bilinear', 'wrap_mode': 'repeat'}


def material_dicts(doc, binary, index, folder):
    m = doc['materials'][index]
    pbr = m.get('pbrMetallicRoughness', {})
    factor = pbr.get('baseColorFactor', [1, 1, 1, 1])[:3]
    if 'baseColorTexture' in pbr:
        if factor != [1, 1, 1]:
            sys.exit('a textured base colour with a factor other than 1 is not supported here')
        base = texture_dict(doc, binary, pbr['baseColorTexture'], folder)
    else:
        base = {'type': 'rgb', 'value': factor}
    bsdf = {'type': 'gltf_brdf', 'base_color': base,
            'metallic': pbr.get('metallicFactor', 1.0), 'roughness': pbr.get('roughnessFactor', 1.0)}
    strength = m.get('extensions', {}).get('KHR_materials_emissive_strength', {}).get('emissiveStrength', 1.0)
    emission = [c * strength for c in m.get('emissiveFactor', [0, 0, 0])]
    emitter = {'type': 'area', 'radiance': {'type': 'rgb', 'value': emission}} if max(emission) > 0 else None
    return bsdf, emitter


def light_dict(doc, node):
    """The node's KHR_lights_punctual light as a Mitsuba emitter, in fovea's units (glTF
    colour x intensity one for one: a point or spot of I cd has radiant intensity I, a
    directional light of E lux gives irradiance E on a surface facing it)."""
    index = node['extensions']['KHR_lights_punctual']['light']
    light = doc['extensions']['KHR_lights_punctual']['lights'][index]
    matrix = node_matrix(node)
    position = matrix[:3, 3].tolist()
    axis = -matrix[:3, 2] / np.linalg.norm(matrix[:3, 2])  # the node's -Z: where light travels
    value = [c * light.get('intensity', 1.0) for c in light.get('color', [1, 1, 1])]
    rgb = {'type': 'rgb', 'value': value}
    kind = light['type']
    if kind == 'directional':
        # Mitsuba's `irradiance` is that on a surface facing the light: E as it is.
        return {'type': 'directional', 'direction': axis.tolist(), 'irradiance': rgb}
    if kind == 'point' and 'range' not in light:
        # Mitsuba's `intensity` is radiant intensity (irradiance I / d^2 facing it): I as it is.
        return {'type': 'point', 'position': position, 'intensity': rgb}
    # A spot, or a point with a range: the extension's falloffs (GltfPunctual).
    scale, offset = 0.0, 1.0
    if kind == 'spot':
        spot = light['spot']
        cos_inner = math.cos(spot.get('innerConeAngle', 0.0))
        cos_outer = math.cos(spot.get('outerConeAngle', math.pi / 4))
        scale = 1 / max(1e-3, cos_inner - cos_outer)
        offset = -cos_outer * scale
    return {'type': 'gltf_punctual', 'position': mi.ScalarPoint3f(position),
            'direction': mi.ScalarVector3f(axis.tolist()), 'intensity': mi.ScalarColor3f(value),
            'range': float(light.get('range', 0.0)), 'scale': scale, 'offset': offset}


def mitsuba_env(path, rotate_deg, folder):
    """An `envmap` that reads radiance as fovea does for `--env path --env-rotate rotate_deg`.

    fovea (src/scene/env_map.rs, glsl/environment.glsl): world direction d is turned back by
    the rotation, m = R_y(-rotate) d (R_y right-handed about +Y), and m reads column
    u = 0.5 + atan2(m.z, m.x) / 2pi and row t = acos(m.y) / pi, bilinearly between texel
    centres (x = u w - 0.5, wrapping; y = t h - 0.5, clamped at the poles); negative texels
    are set to 0.
    Mitsuba 3.9's envmap (measured by evaluating it in known directions on an image whose
    texels hold their own column and row) turns d back by its to_world, v = to_world^-1 d, and
    reads u = atan2(v.x, -v.z) / 2pi between texel centres like fovea (x = u w - 0.5), but
    t = acos(v.y) / pi with its first and last rows at the poles (y = t (h - 1)).
    Columns: fovea's u(m) is Mitsuba's u(v) for v = (-m.z, m.y, m.x) = R_y(-90) m, so
    to_world = R_y(90 + rotate).
    Rows: Mitsuba is given 2h + 1 rows: at t = (j + 0.5) / h fovea's row j, at t = j / h (a
    texel boundary) the mean of the rows either side, the first and last rows at the poles;
    fovea's bilinear surface is linear in t between these, so both interpolate the same."""
    img = np.maximum(np.array(mi.Bitmap(path), dtype=np.float32)[:, :, :3], 0)
    h, w, _ = img.shape
    rows = np.empty((2 * h + 1, w, 3), dtype=np.float32)
    rows[1::2] = img
    rows[2:-1:2] = (img[:-1] + img[1:]) / 2
    rows[0], rows[-1] = img[0], img[-1]
    resampled = os.path.join(folder, 'env-mitsuba.exr')
    mi.Bitmap(rows).write(resampled)
    return {'type': 'envmap', 'filename': resampled,
            'to_world': mi.ScalarTransform4f().rotate([0, 1, 0], 90 + rotate_deg)}


def mitsuba_scene(doc, binary, folder, size, spp, max_depth, env=None):
    scene = {'type': 'scene', 'integrator': {'type': 'path', 'max_depth': max_depth}}
    if env:
        scene['env'] = env
    for k, node in enumerate(doc['nodes']):
        if 'mesh' in node:
            prim = doc['meshes'][node['mesh']]['primitives'][0]
            pos = accessor(doc, binary, prim['attributes']['POSITION'])
            matrix = node_matrix(node)
            world = (np.hstack([pos, np.ones((len(pos), 1))]) @ matrix.T)[:, :3]
            uv = accessor(doc, binary, prim['attributes']['TEXCOORD_0']) if 'TEXCOORD_0' in prim['attributes'] else np.zeros((len(pos), 2))
            normals = None
            if 'NORMAL' in prim['attributes']:
                # Normals transform by the inverse transpose; Mitsuba normalises them.
                normals = accessor(doc, binary, prim['attributes']['NORMAL'])
                normals = normals @ np.linalg.inv(matrix[:3, :3])
            faces = accessor(doc, binary, prim['indices']).reshape(-1, 3)
            if np.linalg.det(matrix[:3, :3]) < 0:
                faces = faces[:, [0, 2, 1]]
            path = os.path.join(folder, f'node{k}.ply')
            write_ply(path, world, uv, faces, normals)
            bsdf, emitter = material_dicts(doc, binary, prim.get('material', 0), folder)
            shape = {'type': 'ply', 'filename': path, 'bsdf': bsdf, 'face_normals': normals is None}
            if emitter:
                shape['emitter'] = emitter
            scene[f'node{k}'] = shape
        elif 'KHR_lights_punctual' in node.get('extensions', {}):
            scene[f'light{k}'] = light_dict(doc, node)
        elif 'camera' in node:
            camera = doc['cameras'][node['camera']]['perspective']
            q = quaternion_matrix(node['rotation'])
            origin = np.array(node['translation'])
            forward, up = -q[:, 2], q[:, 1]
            scene['sensor'] = {
                'type': 'perspective', 'fov_axis': 'y', 'fov': math.degrees(camera['yfov']),
                'to_world': mi.ScalarTransform4f().look_at(origin=origin.tolist(), target=(origin + forward).tolist(), up=up.tolist()),
                'film': {'type': 'hdrfilm', 'width': size, 'height': size, 'rfilter': {'type': 'box'}},
                'sampler': {'type': 'independent', 'sample_count': spp},
            }
    return mi.load_dict(scene)


def block_noise(a, b, block):
    """Per block and channel: the mean of (a + b) / 2, and its standard error from a - b."""
    h, w, _ = a.shape
    mean = ((a + b) / 2).reshape(h // block, block, w // block, block, 3).mean(axis=(1, 3))
    diff = (a - b).reshape(h // block, block, w // block, block, 3)
    # Var(pixel of one render) ~ mean((a-b)^2) / 2; the two-render mean's block mean: / (2 n).
    var = (diff ** 2).mean(axis=(1, 3)) / 2 / (2 * block * block)
    return mean, np.sqrt(var)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('scene')
    ap.add_argument('--fovea', required=True, help='the fovea binary')
    ap.add_argument('--size', type=int, default=64)
    ap.add_argument('--spp', type=int, default=256)
    ap.add_argument('--block', type=int, default=8)
    ap.add_argument('--max-bounces', type=int, default=8)
    ap.add_argument('--z-limit', type=float, default=4.5)
    ap.add_argument('--out', help='keep the renders here')
    ap.add_argument('--env', help='an equirectangular .exr/.hdr lighting both (default: none, '
                    'fovea given a black one in place of its sky)')
    ap.add_argument('--env-rotate', type=float, default=0.0,
                    help="degrees about +Y, as fovea's --env-rotate")
    args = ap.parse_args()
    folder = args.out or tempfile.mkdtemp(prefix='mitsuba-gltf-')
    os.makedirs(folder, exist_ok=True)
    doc, binary = read_glb(args.scene)
    if args.env:
        env = mitsuba_env(args.env, args.env_rotate, folder)
        fovea_env = ['--env', args.env, '--env-rotate', str(args.env_rotate)]
    else:
        # fovea lights a .glb by its gradient sky unless given an environment: a black one
        # leaves the lights and emission alone, as in Mitsuba without an environment.
        env = None
        black = os.path.join(folder, 'black.exr')
        mi.Bitmap(np.zeros((4, 8, 3), dtype=np.float32)).write(black)
        fovea_env = ['--env', black]
    scene = mitsuba_scene(doc, binary, folder, args.size, args.spp, args.max_bounces + 1, env)
    renders = {'mitsuba': [], 'fovea': []}
    for seed in (1, 2):
        img = mi.render(scene, spp=args.spp, seed=seed)
        dr.sync_thread()
        renders['mitsuba'].append(np.array(img)[:, :, :3])
        out = os.path.join(folder, f'fovea-{seed}.exr')
        subprocess.run([args.fovea, 'render', *fovea_env, '--scene', args.scene,
                        '--width', str(args.size), '--height', str(args.size), '--spp', str(args.spp),
                        '--seed', str(seed), '--max-bounces', str(args.max_bounces), '--out', out],
                       check=True, stdout=subprocess.DEVNULL)
        renders['fovea'].append(np.array(mi.Bitmap(out))[:, :, :3])
    for k, img in enumerate(renders['mitsuba']):
        mi.Bitmap(img).write(os.path.join(folder, f'mitsuba-{k + 1}.exr'))
    (mm, ms), (fm, fs) = (block_noise(*renders[k], args.block) for k in ('mitsuba', 'fovea'))
    se = np.maximum(np.sqrt(ms ** 2 + fs ** 2), 1e-3 * np.abs(mm) + 1e-6)
    z = np.abs(mm - fm) / se
    lit = f'env {os.path.basename(args.env)} turned {args.env_rotate:g} deg' if args.env else 'black env'
    print(f'{os.path.basename(args.scene)} ({lit}): {args.size}x{args.size}, {args.spp} spp x 2 '
          f'seeds, {args.block}x{args.block} blocks; mitsuba {mi.__version__}')
    for c, name in enumerate('RGB'):
        print(f'  {name}: mean fovea {fm[:, :, c].mean():.4f}, mitsuba {mm[:, :, c].mean():.4f}; '
              f'worst block z {z[:, :, c].max():.2f}, blocks over 3: {(z[:, :, c] > 3).sum()} of {z[:, :, c].size}')
    print(f'  mean z^2 {np.mean(z * z):.2f} (1 for noise alone); renders in {folder}')
    if z.max() > args.z_limit:
        print(f'FAIL: a block differs by {z.max():.2f} standard errors (limit {args.z_limit})')
        sys.exit(1)
    print('agree within noise')


if __name__ == '__main__':
    main()
