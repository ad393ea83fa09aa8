"""Regenerate `lerobot_tavis/assets/ycb/`: the five YCB objects as scanned, textured meshes fitted to their props.

    python tools/assets/ycb.py --source /path/to/YCB_sim

`--source` is a clone or bare mirror of github.com/vikashplus/YCB_sim holding commit `COMMIT`. Per object the
script reads the scan (`meshes/<id>.msh`, MuJoCo's legacy binary mesh, metres) and its texture
(`textures/<id>.png`, 4096 px), then

1. finds the scan's oriented bounding box and maps its axes onto the prop's (`objects.YCB_OBJECTS`) by rank of
   extent: box props are (x, y, height), cylinders (diameter, diameter, height), so the height axis is vertical;
2. makes the frame right-handed with deterministic signs, then applies the object's `Pose` (turned upside down
   or not, and a yaw) so that the product stands the right way up with its main label facing -x (towards the
   robot at yaw 0); the poses were chosen by looking at renders;
3. centres the mesh on the prop's origin (the centre of its collision shape), scales it per axis onto the
   collision primitive's extents and warps its outline seen from above onto the primitive's (a circle, or a
   rectangle with 2 mm rounded corners), so that its bounding box matches the primitive's at any yaw;
4. decimates it to about `Pose.faces` triangles (MeshLab quadric collapse, texture coordinates kept) and fits
   it again (step 3) to undo the decimation's small shifts;
5. writes `<prop>.obj` (metres, prop frame, texture coordinates for MuJoCo's top-left texture origin) and
   `<prop>.png` (1024 px, the atlas background filled from the nearest chart so that seams do not darken), then
   NOTICE.md and the source's license, into a staging folder that replaces the old one when all is done.
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import trimesh

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import (  # noqa: E402
    Provenance, decimate, read_git_file, staged_group, write_notice, write_obj, write_texture)

from lerobot_tavis.envs.objects import YCB_OBJECTS, PropSpec  # noqa: E402

REPOSITORY = "github.com/vikashplus/YCB_sim"
COMMIT = "57546b87f4724c947eadd4241a7892473febb88d"
LICENSE_FILE = "LICENSE-YCB_sim.txt"
MAX_BYTES = 6_000_000  # the whole group
BOX_CORNER_M = 0.002  # rounding of a box mesh's vertical edges: 0.8 mm inside the box's corners


@dataclass(frozen=True)
class Pose:
    """How one scan is turned after its box axes are mapped onto the prop's, and how finely it is kept.

    `upside_down` turns it 180 degrees about the prop's x axis; `yaw_deg` then turns it about the vertical
    (a multiple of 180 for box props, whose sides must stay on the collision box's; for a can, which of its two
    round axes became x is arbitrary but fixed by the scan, and the yaw brings its label round). `faces` is the
    triangle budget of the decimation (a CPU renderer's time grows with the triangles in view).
    """

    source_id: str
    upside_down: bool
    yaw_deg: float
    faces: int


POSES: dict[str, Pose] = {
    "soup_can": Pose("005_tomato_soup_can", upside_down=False, yaw_deg=0.0, faces=1000),
    "meat_can": Pose("010_potted_meat_can", upside_down=False, yaw_deg=0.0, faces=600),
    "tuna_fish_can": Pose("007_tuna_fish_can", upside_down=False, yaw_deg=60.0, faces=800),
    "gelatin_box": Pose("009_gelatin_box", upside_down=True, yaw_deg=0.0, faces=400),
    "pudding_box": Pose("008_pudding_box", upside_down=False, yaw_deg=180.0, faces=400),
}


def read_msh(data: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertices (V, 3) in metres, per-vertex texture coordinates (V, 2) and triangles (F, 3) of a legacy .msh.

    Layout: int32 nvertex, nnormal, ntexcoord, nface, then float32 vertices, normals, texcoords, int32 faces.
    """
    counts = np.frombuffer(data, "<i4", 4)
    nvertex, nnormal, ntexcoord, nface = (int(c) for c in counts)
    expected = 16 + 4 * (3 * nvertex + 3 * nnormal + 2 * ntexcoord + 3 * nface)
    if len(data) != expected or ntexcoord != nvertex:
        raise SystemExit(f"unexpected .msh layout: counts {counts.tolist()}, {len(data)} bytes (expected {expected})")
    offset = 16
    vertices = np.frombuffer(data, "<f4", 3 * nvertex, offset).reshape(-1, 3).astype(np.float64)
    offset += 4 * 3 * (nvertex + nnormal)
    uv = np.frombuffer(data, "<f4", 2 * ntexcoord, offset).reshape(-1, 2).astype(np.float64)
    offset += 4 * 2 * ntexcoord
    faces = np.frombuffer(data, "<i4", 3 * nface, offset).reshape(-1, 3).astype(np.int64)
    return vertices, uv, faces


def primitive_extents(prop: PropSpec) -> np.ndarray:
    """Full extents (m) of the prop's collision shape along its x, y, z."""
    if prop.shape == "cylinder":
        return np.array([prop.size_m[0], prop.size_m[0], prop.size_m[1]])
    return np.array(prop.size_m)


def upright_rotation(vertices: np.ndarray, faces: np.ndarray, prop: PropSpec, pose: Pose) -> tuple[np.ndarray,
                                                                                                    np.ndarray]:
    """Rotation (3, 3) and centre (3,, m) taking scan coordinates to the prop frame: p_prop = R @ (p - centre).

    The oriented bounding box's i-th shortest axis becomes the prop axis with the i-th shortest extent. Each axis
    is signed so that its largest component is positive, the frame made right-handed by flipping x, then `pose`
    is applied.
    """
    to_box, box_extents = trimesh.bounds.oriented_bounds(trimesh.Trimesh(vertices, faces, process=False))
    box_axes = to_box[:3, :3]  # rows: the box's axes in scan coordinates
    centre = -box_axes.T @ to_box[:3, 3]
    rows = np.empty((3, 3))
    for box_axis, prop_axis in zip(np.argsort(box_extents, kind="stable"),
                                   np.argsort(primitive_extents(prop), kind="stable")):
        axis = box_axes[box_axis]
        rows[prop_axis] = axis * np.sign(axis[np.argmax(np.abs(axis))])
    if np.linalg.det(rows) < 0:
        rows[0] = -rows[0]
    turn = np.diag([1.0, -1.0, -1.0]) if pose.upside_down else np.eye(3)
    c, s = math.cos(math.radians(pose.yaw_deg)), math.sin(math.radians(pose.yaw_deg))
    yaw = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return yaw @ turn @ rows, centre


def fit_to_primitive(vertices: np.ndarray, prop: PropSpec) -> np.ndarray:
    """Centre `vertices` (prop frame) on the collision shape's centre and scale them per axis onto its extents,
    then warp the outline seen from above onto the shape's (`warp_outline`)."""
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    extents = primitive_extents(prop)
    fitted = (vertices - (low + high) / 2) * (extents / (high - low))
    corner = extents[0] / 2 if prop.shape == "cylinder" else BOX_CORNER_M
    return warp_outline(fitted, extents[0] / 2, extents[1] / 2, corner)


def warp_outline(vertices: np.ndarray, half_x: float, half_y: float, corner: float) -> np.ndarray:
    """Stretch vertices away from the vertical axis so that their outline seen from above becomes a rectangle
    (`half_x`, `half_y`, m) with corners rounded to radius `corner` (a circle when corner = half_x = half_y).

    A scan's outline bulges, dents or rounds off by a few millimetres; then the mesh's width would depend on its
    yaw and fingers would sink into or float off it. Each vertex is scaled along its bearing by (distance to the
    target outline) / (distance to the convex hull of all vertices seen from above), both along that bearing:
    the hull lands on the target outline and every vertex stays inside it.
    """
    plan = vertices[:, :2]
    radius = np.linalg.norm(plan, axis=1)
    direction = plan / np.maximum(radius, 1e-12)[:, None]
    warped = vertices.copy()
    warped[:, :2] = plan * (_outline_distance(direction, half_x, half_y, corner)
                            / _hull_distance(direction, plan))[:, None]
    return warped


def _hull_distance(direction: np.ndarray, plan: np.ndarray) -> np.ndarray:
    """Distance from the origin (inside the hull) to the convex hull of `plan` points along each unit direction."""
    hull = plan[cv2.convexHull(plan.astype(np.float32), returnPoints=False).ravel()]
    start, edge = hull, np.roll(hull, -1, axis=0) - hull

    def cross(a, b):
        return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]

    with np.errstate(divide="ignore", invalid="ignore"):
        denominator = cross(direction[:, None, :], edge[None])
        along_ray = cross(start[None], edge[None]) / denominator
        along_edge = cross(start[None], direction[:, None, :]) / denominator
    hits = (along_edge >= -1e-9) & (along_edge <= 1 + 1e-9) & (along_ray > 0)
    return np.where(hits, along_ray, np.inf).min(axis=1)


def _outline_distance(direction: np.ndarray, half_x: float, half_y: float, corner: float) -> np.ndarray:
    """Distance from the centre to a rounded rectangle's outline along each unit direction."""
    c, s = np.abs(direction[:, 0]), np.abs(direction[:, 1])
    with np.errstate(divide="ignore"):
        to_side = np.where(c * (half_y - corner) >= s * half_x, half_x / c, np.inf)
        to_top = np.where(s * (half_x - corner) >= c * half_y, half_y / s, np.inf)
    centre = np.array([half_x - corner, half_y - corner])
    projection = c * centre[0] + s * centre[1]
    to_corner = projection + np.sqrt(np.maximum(projection**2 - centre @ centre + corner**2, 0.0))
    straight = np.minimum(to_side, to_top)
    return np.where(np.isfinite(straight), straight, to_corner)


def build(source: Path, prop: PropSpec, pose: Pose) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(vertices, faces, wedge_uv, texture RGB) of one prop, in its frame, fitted to its collision shape."""
    vertices, uv, faces = read_msh(read_git_file(source, COMMIT, f"meshes/{pose.source_id}.msh"))
    scan_faces = faces
    rotation, centre = upright_rotation(vertices, faces, prop, pose)
    # Fitted before decimating, so that the dense scan fills the collision shape's outline (corners included) and
    # the decimation keeps it, and again after, to undo the decimation's small shifts.
    fitted = fit_to_primitive((vertices - centre) @ rotation.T, prop)
    fitted, faces, wedge_uv = decimate(fitted, faces, pose.faces, vertex_uv=uv)
    wedge_uv = wedge_uv.copy()
    wedge_uv[..., 1] = 1.0 - wedge_uv[..., 1]  # .msh texcoords start top-left; MuJoCo flips an OBJ's v
    png = np.frombuffer(read_git_file(source, COMMIT, f"textures/{pose.source_id}.png"), np.uint8)
    texture = pad_charts(cv2.cvtColor(cv2.imdecode(png, cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB), uv, scan_faces)
    return fit_to_primitive(fitted, prop), faces, wedge_uv, texture


def pad_charts(rgb: np.ndarray, uv: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Give every texel that no triangle maps to the colour of the nearest texel one does.

    The atlas background is black; shrinking the texture and MuJoCo's mipmaps would blend it into the charts'
    edges, drawing dark lines along the texture seams. `uv` (V, 2) are .msh coordinates (origin top-left).
    """
    height, width = rgb.shape[:2]
    fixed_point = 16  # cv2.fillPoly with shift=4
    corners = np.round(uv[faces] * (width, height) * fixed_point).astype(np.int32)
    used = np.zeros((height, width), np.uint8)
    cv2.fillPoly(used, list(corners), 1, shift=4)
    used = cv2.dilate(used, np.ones((3, 3), np.uint8))  # texels the rasteriser's edges may have missed
    _, labels = cv2.distanceTransformWithLabels(1 - used, cv2.DIST_L2, 5, labelType=cv2.DIST_LABEL_PIXEL)
    rows, cols = np.nonzero(used)  # raster order, the order in which the labels number the used texels
    if not np.array_equal(labels[rows, cols], np.arange(1, len(rows) + 1)):
        raise SystemExit("unexpected label order from cv2.distanceTransformWithLabels")
    nearest = labels - 1
    return rgb[rows[nearest], cols[nearest]]


def check_commit(source: Path) -> None:
    result = subprocess.run(["git", "-C", str(source), "cat-file", "-e", f"{COMMIT}^{{commit}}"],
                            capture_output=True)
    if result.returncode != 0:
        raise SystemExit(f"{source} does not hold commit {COMMIT} of {REPOSITORY}: clone or fetch it first")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--source", type=Path, required=True, help="clone or bare mirror of YCB_sim")
    args = parser.parse_args()
    check_commit(args.source)
    if set(POSES) != set(YCB_OBJECTS):
        raise SystemExit(f"POSES {sorted(POSES)} must name exactly the YCB props {sorted(YCB_OBJECTS)}")
    with staged_group("ycb", MAX_BYTES) as staging:
        entries = []
        for name, pose in POSES.items():
            vertices, faces, wedge_uv, texture = build(args.source, YCB_OBJECTS[name], pose)
            write_obj(staging / f"{name}.obj", vertices, faces, wedge_uv)
            write_texture(staging / f"{name}.png", texture)
            print(f"{name}: {len(faces)} triangles, extents (mm) {np.ptp(vertices, axis=0) * 1000}")
            extents = " x ".join(f"{e * 1000:.2f}" for e in primitive_extents(YCB_OBJECTS[name]))
            changes = (f"turned upright (label towards -x), centred, scaled per axis and its outline warped onto the "
                       f"collision shape ({extents} mm), decimated from 16,384 to {len(faces)} triangles, "
                       "written as OBJ")
            entries += [
                Provenance(f"{name}.obj", REPOSITORY, COMMIT, f"meshes/{pose.source_id}.msh", LICENSE, changes),
                Provenance(f"{name}.png", REPOSITORY, COMMIT, f"textures/{pose.source_id}.png", LICENSE,
                           "atlas background filled with the nearest chart's colours, shrunk from 4096 to 1024 px"),
            ]
        (staging / LICENSE_FILE).write_bytes(read_git_file(args.source, COMMIT, "LICENSE"))
        write_notice(staging, "YCB objects", INTRO, entries)


LICENSE = "CC BY 4.0 (YCB models); Apache-2.0 (YCB_sim)"
INTRO = """\
Scanned meshes and textures of five objects of the YCB Object and Model Set (Yale-CMU-Berkeley): B. Calli,
A. Walsman, A. Singh, S. Srinivasa, P. Abbeel, A. M. Dollar, "Benchmarking in Manipulation Research: Using the
Yale-CMU-Berkeley Object and Model Set", IEEE Robotics & Automation Magazine 22(3), 2015;
https://www.ycbbenchmarks.com/. The YCB models are licensed under the Creative Commons Attribution 4.0
International license (CC BY 4.0, https://creativecommons.org/licenses/by/4.0/). We took them from their MuJoCo
conversion in the YCB_sim repository by Vikash Kumar (Apache-2.0, `LICENSE-YCB_sim.txt`). We changed them as the
table says: each object was turned upright, fitted onto the benchmark's 0.75-scale collision shape (per-axis
scaling and a warp of its outline seen from above), decimated and converted to OBJ; each texture was padded and
shrunk. Regenerate them with `python tools/assets/ycb.py --source <YCB_sim clone>`."""

if __name__ == "__main__":
    main()
