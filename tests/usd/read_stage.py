"""Reads a USD file with Pixar's own library (pip package usd-core) and
prints what a pipeline sees as JSON: the stage's metadata, every mesh with
its points and normals at each time sample and halfway between the first
two, texture coordinates, colours and bound material, and the findings of
every validator USD ships (UsdValidation).

    python read_stage.py FILE.usda|FILE.usdc

Exit status: 0 when a report was printed, 2 on bad usage, 3 when USD could
not open the file. Install with
`python3 -m venv tests/usd/.venv && tests/usd/.venv/bin/pip install -r tests/usd/requirements.txt`.
"""

import json
import sys

from pxr import Sdf, Usd, UsdGeom, UsdShade, UsdValidation


def vectors(value):
    return [list(v) for v in value] if value is not None else None


def primvar(mesh, name):
    var = UsdGeom.PrimvarsAPI(mesh.GetPrim()).GetPrimvar(name)
    if not var or not var.HasValue():
        return None
    return {
        "interpolation": var.GetInterpolation(),
        "type": str(var.GetTypeName()),
        "value": vectors(var.Get()) if var.GetTypeName().isArray and
        hasattr(var.Get()[0], "__len__") else list(var.Get()),
    }


def mesh_report(mesh):
    prim = mesh.GetPrim()
    points = mesh.GetPointsAttr()
    normals = mesh.GetNormalsAttr()
    times = points.GetTimeSamples()
    report = {
        "path": str(prim.GetPath()),
        "type": prim.GetTypeName(),
        "face_vertex_counts": list(mesh.GetFaceVertexCountsAttr().Get()),
        "face_vertex_indices": list(mesh.GetFaceVertexIndicesAttr().Get()),
        "double_sided": mesh.GetDoubleSidedAttr().Get(),
        "orientation": mesh.GetOrientationAttr().Get(),
        "subdivision_scheme": mesh.GetSubdivisionSchemeAttr().Get(),
        "point_times": list(times),
        "normal_times": list(normals.GetTimeSamples()) if normals.HasValue() else None,
        "normals_interpolation": mesh.GetNormalsInterpolation() if normals.HasValue() else None,
        "st": primvar(mesh, "st"),
        "display_color": primvar(mesh, "displayColor"),
        "display_opacity": primvar(mesh, "displayOpacity"),
    }
    sample_times = list(times) if times else [Usd.TimeCode.Default()]
    report["points"] = [vectors(points.Get(t)) for t in sample_times]
    report["normals"] = (
        [vectors(normals.Get(t)) for t in sample_times] if normals.HasValue() else None
    )
    report["extents"] = [vectors(mesh.GetExtentAttr().Get(t)) for t in sample_times]
    # What USD computes from the points, to compare with the authored extent.
    report["computed_extents"] = [
        vectors(UsdGeom.Boundable.ComputeExtentFromPlugins(mesh, t)) for t in sample_times
    ]
    if len(times) >= 2:
        halfway = 0.5 * (times[0] + times[1])
        report["points_halfway"] = {"time": halfway, "points": vectors(points.Get(halfway))}
    material, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()
    if material:
        shader = material.ComputeSurfaceSource()[0]
        report["material"] = {
            "path": str(material.GetPath()),
            "shader_id": shader.GetIdAttr().Get() if shader else None,
            "diffuse_color": list(shader.GetInput("diffuseColor").Get()) if shader else None,
            "opacity": shader.GetInput("opacity").Get() if shader else None,
        }
        # Where the diffuse colour comes from when it is connected: the
        # source shader's id and the primvar it reads.
        if shader and shader.GetInput("diffuseColor").HasConnectedSource():
            source = shader.GetInput("diffuseColor").GetConnectedSources()[0][0]
            reader = UsdShade.Shader(source.source.GetPrim())
            found = {
                "shader_id": reader.GetIdAttr().Get(),
                "output": source.sourceName,
            }
            if reader.GetInput("varname"):
                found["varname"] = reader.GetInput("varname").Get()
            # A texture: its file as written and as USD resolves it (None
            # when the file is not there), its colour space, wrap modes and
            # scale, and what its st input reads.
            if reader.GetInput("file"):
                asset = reader.GetInput("file").Get()
                found["file"] = asset.path
                found["resolved_file"] = asset.resolvedPath or None
                for name in ["sourceColorSpace", "wrapS", "wrapT"]:
                    found[name] = reader.GetInput(name).Get()
                found["scale"] = list(reader.GetInput("scale").Get())
                st = reader.GetInput("st")
                if st and st.HasConnectedSource():
                    st_reader = UsdShade.Shader(st.GetConnectedSources()[0][0].source.GetPrim())
                    found["st"] = {
                        "shader_id": st_reader.GetIdAttr().Get(),
                        "varname": st_reader.GetInput("varname").Get(),
                    }
            report["material"]["diffuse_source"] = found
    return report


def main():
    if len(sys.argv) != 2:
        print("usage: python read_stage.py FILE.usda|FILE.usdc", file=sys.stderr)
        return 2
    path = sys.argv[1]
    try:
        layer = Sdf.Layer.FindOrOpen(path)
        stage = Usd.Stage.Open(path) if layer else None
    except Exception as error:  # pxr raises Tf.ErrorException on parse errors
        print(f"USD cannot open {path}: {error}", file=sys.stderr)
        return 3
    if not stage:
        print(f"USD cannot open {path}", file=sys.stderr)
        return 3
    validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    findings = UsdValidation.ValidationContext(validators).Validate(stage)
    default_prim = stage.GetDefaultPrim()
    report = {
        "usd_version": list(Usd.GetVersion()),
        "file_format": layer.GetFileFormat().formatId,
        "default_prim": str(default_prim.GetPath()) if default_prim else None,
        "default_prim_type": default_prim.GetTypeName() if default_prim else None,
        "default_prim_kind": Usd.ModelAPI(default_prim).GetKind() if default_prim else None,
        "up_axis": UsdGeom.GetStageUpAxis(stage),
        "meters_per_unit": UsdGeom.GetStageMetersPerUnit(stage),
        "start_time_code": stage.GetStartTimeCode(),
        "end_time_code": stage.GetEndTimeCode(),
        "time_codes_per_second": stage.GetTimeCodesPerSecond(),
        "frames_per_second": stage.GetFramesPerSecond(),
        "meshes": [
            mesh_report(UsdGeom.Mesh(prim))
            for prim in stage.Traverse()
            if prim.IsA(UsdGeom.Mesh)
        ],
        "validators": [v.GetMetadata().name for v in validators],
        "validation_findings": [f.GetErrorAsString() for f in findings if not f.HasNoError()],
    }
    print(json.dumps(report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
