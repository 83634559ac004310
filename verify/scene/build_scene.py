# Builds the measured scene that `colorlab scene` exported (scene.json beside this script) in Blender 3.4
# and renders it with Cycles on the CPU (docs/verify.md, "The measured scene"):
#
#   blender -b --factory-startup -noaudio -P build_scene.py -- [--scene scene.json] [--out renders]
#       [--mode bands|luminance] [--bands 450,550,...] [--size 320x240] [--samples 32] [--seed 0]
#       [--view camera|top] [--threads 0]
#
# bands:     one render per wavelength band (default: every band of scene.json): each surface's reflectance in
#            that band as a grey albedo, each lamp's spectral radiance in that band (times the band width) as
#            its emission. Light transport is linear in each wavelength and nothing fluoresces, so the stack of
#            band images is the scene's spectral radiance. Files: band_<nm>nm.exr, W·sr⁻¹·m⁻² per band.
# luminance: one render per lamp, its emitter's luminance as emission and each surface's luminous reflectance
#            under that lamp as albedo: the image is the floor's and chart's luminance in cd/m² (exact for one
#            lamp, because every surface is grey in luminance under it). Files: luminance_<lamp>.exr.
# The view: "camera" is scene.json's camera — with a pose from the located chart, its axes, position and principal
#            point (give --size with the photograph's aspect, resolution_px, for the photograph's frame); "top" looks straight down from just below the lamps with an
#            orthographic lens whose frame spans the cabinet's width, pixel (i, j) centred on floor point
#            ((i + ½)·w/W, depth − (j + ½)·w/W) — the floor as an imaging luminance meter.
# Every image: 32-bit float OpenEXR, RGB all equal, view transform Standard, no denoising, fixed seed.
import argparse
import json
import math
import os
import sys

import bpy


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    here = os.path.dirname(os.path.abspath(__file__))
    p = argparse.ArgumentParser(prog="build_scene.py")
    p.add_argument("--scene", default=os.path.join(here, "scene.json"))
    p.add_argument("--out", default=os.path.join(here, "renders"))
    p.add_argument("--mode", choices=["bands", "luminance"], default="bands")
    p.add_argument("--bands", default="", help="band centres in nm, comma-separated (default: all)")
    p.add_argument("--size", default="320x240")
    p.add_argument("--samples", type=int, default=32)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--view", choices=["camera", "top"], default="camera")
    p.add_argument("--threads", type=int, default=0, help="0: Blender's choice")
    a = p.parse_args(argv)
    try:
        w, h = (int(v) for v in a.size.lower().split("x"))
    except ValueError:
        p.error("--size must be WIDTHxHEIGHT, e.g. 320x240")
    if w < 1 or h < 1 or a.samples < 1:
        p.error("--size and --samples must be positive")
    a.width, a.height = w, h
    return a


def band_values(spectrum, centres):
    out = []
    for nm in centres:
        k = (nm - spectrum["first_nm"]) / spectrum["step_nm"]
        i = int(round(k))
        if abs(k - i) > 1e-6 or not 0 <= i < len(spectrum["values"]):
            raise SystemExit("build_scene.py: band %g nm is not on the scene's grid" % nm)
        out.append(spectrum["values"][i])
    return out


def plane(name, centre, size, z, flip=False):
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(centre[0], centre[1], z))
    obj = bpy.context.active_object
    obj.name = name
    obj.scale = (size[0], size[1], 1.0)
    if flip:  # normal down: an emitter in the ceiling, or a ceiling seen from inside
        obj.rotation_euler = (math.pi, 0.0, 0.0)
    return obj


def wall(name, centre, size, rotation):
    obj = plane(name, centre[:2], size, centre[2])
    obj.rotation_euler = rotation
    return obj


def diffuse(name, albedo):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes = m.node_tree.nodes
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    bsdf = nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Roughness"].default_value = 0.0  # Lambertian
    m.node_tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    set_albedo(m, albedo)
    return m


def set_albedo(m, albedo):
    m.node_tree.nodes["Diffuse BSDF"].inputs["Color"].default_value = (albedo, albedo, albedo, 1.0)


def emitter(name):
    # Emits from its front face only (its back faces the black ceiling), Lambertian as Cycles' emission is.
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes = m.node_tree.nodes
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    front = nodes.new("ShaderNodeEmission")
    front.name = "front"
    back = nodes.new("ShaderNodeEmission")
    back.inputs["Strength"].default_value = 0.0
    geometry = nodes.new("ShaderNodeNewGeometry")
    mix = nodes.new("ShaderNodeMixShader")
    links = m.node_tree.links
    links.new(geometry.outputs["Backfacing"], mix.inputs["Fac"])
    links.new(front.outputs["Emission"], mix.inputs[1])
    links.new(back.outputs["Emission"], mix.inputs[2])
    links.new(mix.outputs["Shader"], out.inputs["Surface"])
    return m


def set_emission(m, strength):
    node = m.node_tree.nodes["front"]
    node.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    node.inputs["Strength"].default_value = strength


def build(scene_doc, args):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    cab = scene_doc["cabinet"]
    w, d, h = cab["width_m"], cab["depth_m"], cab["height_m"]
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world

    black = diffuse("walls", cab["walls_reflectance"])
    floor_mat = diffuse("floor", cab["floor_reflectance"])
    plane("floor", (w / 2, d / 2), (w, d), 0.0).data.materials.append(floor_mat)
    # The lamps' plane is the cabinet's height; the black ceiling sits 1 mm above it so the two never coincide.
    plane("ceiling", (w / 2, d / 2), (w, d), h + 0.001, flip=True).data.materials.append(black)
    wall("left", (0.0, d / 2, h / 2), (h, d), (0.0, math.pi / 2, 0.0)).data.materials.append(black)
    wall("right", (w, d / 2, h / 2), (h, d), (0.0, -math.pi / 2, 0.0)).data.materials.append(black)
    wall("back", (w / 2, d, h / 2), (w, h), (math.pi / 2, 0.0, 0.0)).data.materials.append(black)

    lamps = {}
    for lamp in scene_doc["lamps"]:
        e = lamp["emitter"]
        m = emitter("lamp " + lamp["name"])
        plane("lamp " + lamp["name"], e["center_m"][:2], e["size_m"], e["center_m"][2], flip=True).data.materials.append(m)
        lamps[lamp["name"]] = (lamp, m)

    chart = scene_doc["chart"]
    # The chart lies on the floor; 10 and 20 µm above it keep the surfaces distinct without moving the light
    # they receive measurably (the irradiance changes by ~2·z/h, under 1e-4).
    plane("chart", chart["center_m"], chart["size_m"], 1e-5).data.materials.append(diffuse("chart board", chart["surround_reflectance"]))
    patches = []
    for p in chart["patches"]:
        m = diffuse("patch " + p["id"], 0.0)
        s = p["size_m"]
        plane("patch " + p["id"], p["center_m"], (s, s), 2e-5).data.materials.append(m)
        patches.append((p, m))

    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y, r.resolution_percentage = args.width, args.height, 100
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "32"
    r.image_settings.color_mode = "RGB"
    r.image_settings.exr_codec = "ZIP"
    if args.threads > 0:
        r.threads_mode, r.threads = "FIXED", args.threads
    c = scene.cycles
    c.device = "CPU"
    c.samples = args.samples
    c.use_denoising = False
    c.use_adaptive_sampling = False
    c.seed = args.seed
    c.use_animated_seed = False
    c.filter_width = 0.01  # each pixel samples its own centre: the image is the field at pixel centres
    scene.display_settings.display_device = "sRGB"
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0

    cam_data = bpy.data.cameras.new("camera")
    cam = bpy.data.objects.new("camera", cam_data)
    scene.collection.objects.link(cam)
    scene.camera = cam
    if args.view == "top":
        cam_data.type = "ORTHO"
        cam_data.ortho_scale = w
        cam_data.sensor_fit = "HORIZONTAL"
        cam_data.clip_start = 1e-4
        cam.location = (w / 2, d - (w * args.height / args.width) / 2, h - 0.002)
        cam.rotation_euler = (0.0, 0.0, 0.0)  # looking down -z, image up = +y (the back)
    else:
        k = scene_doc["camera"]
        cam_data.lens = k["focal_length_mm"]
        cam_data.sensor_fit = "HORIZONTAL"
        cam_data.sensor_width = k["sensor_mm"][0]
        cam_data.clip_start = 1e-3
        import mathutils
        if "axes" in k:
            # The pose from the located chart: OpenCV's camera axes (x right, y down, z forward) in the cabinet;
            # Blender's camera looks down its -Z with +Y up, so its axes are (x, -y, -z).
            x, y, z = (mathutils.Vector(a) for a in k["axes"])
            rot = mathutils.Matrix((x, -y, -z)).transposed()
            cam.matrix_world = mathutils.Matrix.Translation(k["position_m"]) @ rot.to_4x4()
            # The principal point off the frame's centre: Blender's shift, in units of the frame's larger side.
            w_px, h_px = k["resolution_px"]
            ip = k["intrinsics_px"]
            cam_data.shift_x = ((w_px - 1) / 2.0 - ip["cx"]) / max(w_px, h_px)
            cam_data.shift_y = (ip["cy"] - (h_px - 1) / 2.0) / max(w_px, h_px)
        else:
            cam.location = k["position_m"]
            look = [k["look_at_m"][i] - k["position_m"][i] for i in range(3)]
            cam.rotation_euler = mathutils.Vector(look).to_track_quat("-Z", "Y").to_euler()
    return scene, lamps, patches, floor_mat


def render(scene, path):
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)


def main():
    args = parse_args()
    with open(args.scene, encoding="utf-8") as f:
        doc = json.load(f)
    if doc.get("schema") != "colorlab-scene/1":
        raise SystemExit("build_scene.py: %s is not a colorlab-scene/1 document" % args.scene)
    os.makedirs(args.out, exist_ok=True)
    scene, lamps, patches, floor_mat = build(doc, args)
    b = doc["bands"]
    grid = [b["first_nm"] + b["step_nm"] * i for i in range(b["count"])]
    floor_r = doc["cabinet"]["floor_reflectance"]
    written = []
    if args.mode == "bands":
        centres = [float(v) for v in args.bands.split(",")] if args.bands else grid
        for nm in centres:
            for lamp, m in lamps.values():
                set_emission(m, band_values(lamp["spectral_radiance"], [nm])[0] * b["step_nm"])
            for p, m in patches:
                set_albedo(m, band_values(p["reflectance"], [nm])[0])
            path = os.path.join(args.out, "band_%gnm.exr" % nm)
            render(scene, path)
            written.append({"file": os.path.basename(path), "band_nm": nm, "units": "W·sr⁻¹·m⁻² in the band"})
    else:
        ybar = b["ybar"]
        for name, (lamp, m) in lamps.items():
            for other, om in lamps.values():
                set_emission(om, lamp["luminance_cd_m2"] if om is m else 0.0)
            weight = [s * y for s, y in zip(band_values(lamp["spectral_radiance"], grid), ybar)]
            total = sum(weight)
            for p, pm in patches:
                refl = band_values(p["reflectance"], grid)
                set_albedo(pm, sum(r * wgt for r, wgt in zip(refl, weight)) / total)
            path = os.path.join(args.out, "luminance_%s.exr" % name)
            render(scene, path)
            written.append({"file": os.path.basename(path), "lamp": name, "units": "cd/m²"})
    with open(os.path.join(args.out, "renders.json"), "w", encoding="utf-8") as f:
        json.dump({"scene": os.path.abspath(args.scene), "mode": args.mode, "view": args.view, "size": [args.width, args.height],
                   "samples": args.samples, "seed": args.seed, "floor_reflectance": floor_r, "renders": written}, f, indent=1)


main()
