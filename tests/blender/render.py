"""Renders an exported .glb (or a USD layer) in Blender, headless, for the
end-to-end test app/tests/blender.rs and the README's pictures: the file
goes through Blender's own glTF (or USD) importer,
its animation is played to chosen times and each time is drawn by the
Workbench engine, seen by the camera `anthesis render` wrote to
camera.json.

    tests/blender/.venv/bin/python tests/blender/render.py JOB.json

JOB.json: { "file": "/abs/lily.glb" (or .usdc, .usda, .usd), "width": W, "height": H,
  "times": [seconds, ...], "fps": keyframes per second of the file,
  "camera": { "eye": [x,y,z], "target": [x,y,z], "up": [x,y,z],
              "vertical_fov_deg": F, "near": N } (glTF axes, Y up),
  "looks": ["albedo", "ids", "studio"] (optional; these three by default),
  "out": "/abs/folder" }

For time I it writes OUT/blender-I-LOOK.png:
- albedo: every material's base colour as Blender shows it (its base-colour
  texture, or its colour where it has none), unlit ("Flat" lighting,
  "Texture" colour), on a transparent background;
- ids (a .glb only): mesh i of the file (in file order) in a flat colour of full green,
  n = i + 1 in its red and blue (red = 8 (n mod 32), blue = 8 (n div 32)),
  on a transparent background;
- studio: Workbench's studio lighting over the same colours, on a
  transparent background (a picture for people, not compared).

Writes OUT/report.json: Blender's version, the imported meshes in file
order with their shape keys, the animation's frame range, and per time the
Blender frame shown and the pixels of each mesh in the ids picture.

Workbench, not Eevee or Cycles: it draws with OpenGL through Mesa's
software rasterizer (EGL, no display, no GPU) in well under a second per
picture at this size, and its flat texture mode shows the imported base
colour exactly, with no light to tell apart from the painted colour.
Exit status: 0 when the report was written, 2 on bad usage, 3 when Blender
failed to import or render.
"""

import json
import math
import sys

import bpy
from mathutils import Matrix, Vector


def fail(status, message):
    print(message, file=sys.stderr)
    sys.exit(status)


def blender_axes(v):
    """A glTF vector (Y up) in Blender's axes (Z up), as the importer turns them."""
    x, y, z = v
    return Vector((x, -z, y))


def srgb_to_linear(c):
    if c <= 0.04045:
        return c / 12.92
    return ((c + 0.055) / 1.055) ** 2.4


def mesh_id_colour(i):
    """Scene-linear colour that the Standard view transform writes as the
    8-bit sRGB colour red = 8 (n mod 32), green = 255, blue = 8 (n div 32)
    for n = i + 1 (up to 1,023 meshes)."""
    n = i + 1
    return (srgb_to_linear(8 * (n % 32) / 255), 1.0, srgb_to_linear(8 * (n // 32) / 255), 1.0)


def place_camera(scene, spec, width, height):
    eye = blender_axes(spec["eye"])
    target = blender_axes(spec["target"])
    up = blender_axes(spec["up"])
    forward = (target - eye).normalized()
    right = forward.cross(up).normalized()
    true_up = right.cross(forward)
    # A Blender camera looks down its -Z with +Y up.
    rotation = Matrix((right, true_up, -forward)).transposed()
    camera = bpy.data.cameras.new("anthesis camera")
    camera.sensor_fit = "VERTICAL"
    camera.angle_y = math.radians(spec["vertical_fov_deg"])
    camera.clip_start = spec["near"]
    camera.clip_end = 1e6
    obj = bpy.data.objects.new("anthesis camera", camera)
    obj.matrix_world = Matrix.Translation(eye) @ rotation.to_4x4()
    scene.collection.objects.link(obj)
    scene.camera = obj
    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = 1.0
    scene.render.pixel_aspect_y = 1.0


def meshes_in_file_order(path):
    """The file's meshes (by node name) in the order of its "nodes": the
    importer does not keep the file's order, the ids picture needs it."""
    with open(path, "rb") as f:
        header = f.read(20)
        length = int.from_bytes(header[12:16], "little")
        document = json.loads(f.read(length))
    names = []
    for node in document.get("nodes", []):
        if "mesh" in node:
            names.append(node.get("name", document["meshes"][node["mesh"]].get("name")))
    return names


def main():
    if len(sys.argv) != 2:
        fail(2, "usage: python render.py JOB.json")
    with open(sys.argv[1]) as f:
        job = json.load(f)
    width, height = job["width"], job["height"]
    looks = job.get("looks", ["albedo", "ids", "studio"])

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    fps = job["fps"]
    # Whole frames per keyframe: the importer keys time t at frame t * fps.
    scene.render.fps = round(fps)
    scene.render.fps_base = round(fps) / fps
    if job["file"].endswith((".usd", ".usda", ".usdc")):
        # Blender's USD importer: time code k at frame k, the layer's Y up
        # turned to Blender's Z up as the glTF importer does (so the same
        # camera), its UsdPreviewSurface and UsdUVTexture as a Principled
        # BSDF fed by an Image Texture.
        if "FINISHED" not in bpy.ops.wm.usd_import(filepath=job["file"]):
            fail(3, f"Blender's USD importer did not import {job['file']}")
        names = sorted(o.name for o in scene.objects if o.type == "MESH")
        if "ids" in looks:
            fail(2, "the ids look needs a .glb (its meshes in file order)")
    else:
        if "FINISHED" not in bpy.ops.import_scene.gltf(filepath=job["file"]):
            fail(3, f"Blender's glTF importer did not import {job['file']}")
        names = meshes_in_file_order(job["file"])
    objects = []
    for name in names:
        found = [o for o in scene.objects if o.type == "MESH" and o.name in (name, name.replace(" ", "_"))]
        if not found:
            fail(3, f"no mesh object named {name!r} after the import")
        objects.append(found[0])

    place_camera(scene, job["camera"], width, height)
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.render.film_transparent = True
    scene.render.dither_intensity = 0.0
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGBA"
    scene.render.image_settings.color_depth = "8"
    # Colours written as they are: no filmic curve, no look, no exposure.
    scene.display_settings.display_device = "sRGB"
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    shading = scene.display.shading
    # Each side of an organ whose sides differ is its own single-sided
    # primitive: culling back faces shows each side its own colours.
    shading.show_backface_culling = True
    shading.show_cavity = False
    shading.show_shadows = False
    shading.show_object_outline = False
    shading.show_specular_highlight = False
    # One sample per pixel: crisp silhouettes, the texture's own colours.
    scene.display.render_aa = "OFF"

    # A material without a base-colour texture shows its display colour in
    # Texture mode: the importer sets it from baseColorFactor; set it again
    # from the node tree so that the two cannot disagree.
    for material in bpy.data.materials:
        tree = material.node_tree
        bsdf = tree and next((n for n in tree.nodes if n.type == "BSDF_PRINCIPLED"), None)
        if bsdf and not bsdf.inputs["Base Color"].is_linked:
            material.diffuse_color = tuple(bsdf.inputs["Base Color"].default_value)
    for i, obj in enumerate(objects):
        obj.color = mesh_id_colour(i)

    action_ranges = sorted({tuple(a.frame_range) for a in bpy.data.actions})
    frames = []
    for index, time in enumerate(job["times"]):
        frame = time * scene.render.fps / scene.render.fps_base
        whole = math.floor(frame + 1e-6)
        scene.frame_set(whole, subframe=max(0.0, frame - whole))
        report = {"time": time, "frame": frame}
        for look in looks:
            if look == "albedo":
                shading.light = "FLAT"
                shading.color_type = "TEXTURE"
            elif look == "ids":
                shading.light = "FLAT"
                shading.color_type = "OBJECT"
            elif look == "studio":
                shading.light = "STUDIO"
                shading.color_type = "TEXTURE"
            else:
                fail(2, f"unknown look {look!r}")
            path = f"{job['out']}/blender-{index}-{look}.png"
            scene.render.filepath = path
            bpy.ops.render.render(write_still=True)
            report[look] = path
            if look == "ids":
                report["pixels"] = count_ids(path, names)
        frames.append(report)

    with open(f"{job['out']}/report.json", "w") as f:
        json.dump(
            {
                "blender": bpy.app.version_string,
                "meshes": names,
                "shape_keys": {
                    o.name: len(o.data.shape_keys.key_blocks) - 1 if o.data.shape_keys else 0
                    for o in objects
                },
                "action_frame_ranges": action_ranges,
                "frames": frames,
            },
            f,
            indent=1,
        )


def count_ids(path, names):
    image = bpy.data.images.load(path)
    pixels = list(image.pixels)
    counts = {name: 0 for name in names}
    for p in range(0, len(pixels), 4):
        if pixels[p + 3] < 0.5 or pixels[p + 1] < 0.99:
            continue
        # Stored as it was written (8-bit sRGB), read back as floats in 0..1.
        index = round(pixels[p] * 255 / 8) + 32 * round(pixels[p + 2] * 255 / 8) - 1
        if 0 <= index < len(names):
            counts[names[index]] += 1
    bpy.data.images.remove(image)
    return counts


if __name__ == "__main__":
    main()
