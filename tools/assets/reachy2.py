"""Regenerate `lerobot_tavis/assets/reachy2/`: Pollen Robotics' Reachy 2 visual meshes, baked into the body frames of
our procedural Reachy2 (`lerobot_tavis/envs/robots/reachy2.py`), and the `visuals.json` manifest that dresses it.

    python tools/assets/reachy2.py --source /path/to/reachy2_mujoco    # a clone or bare mirror holding COMMIT

Source: github.com/pollen-robotics/reachy2_mujoco (Apache-2.0) at COMMIT. The kinematics come from its MJCF
`reachy2.xml`, the meshes from the COLLADA files of its `original_urdf/`: the MJCF's OBJ meshes were converted from
them vertex for vertex (checked below) but lost their materials, which colour our parts; and the MJCF's
`upper_arm_visual.obj` (over 4 MB) is missing from size-limited mirrors.

Steps:
1. Compile the source MJCF (kinematics only) and our undressed Reachy2, both at the zero pose with their bases at the
   world origin. Each source body that carries a visual mesh maps to one of our bodies (BODY_MAP); the script
   checks that the mapped pair keeps a constant relative pose at random arm and neck poses, so a mesh baked at the
   zero pose follows our joints.
2. Split every visual mesh by source material (and, for the head, by region) into our few materials, wrap each
   piece into one closed surface (CGAL alpha wrap: the CAD exports are soups of open patches that do not decimate),
   decimate it (MeshLab quadric collapse), bake it into its target body frame (metres) and write binary STL, one
   file per body and material.
3. Gripper: the pincette base goes on `<p>_hand`. Our fingers slide; the real ones are a four-bar linkage whose distal
   link keeps its orientation while its proximal link swings. So each slide finger body carries the distal link only,
   shifted so that its tip and inner face coincide with our collision pad at every opening (our fingers are 29 mm
   shorter than the real ones and centred on the palm); the swinging proximal links cannot follow a slide joint and
   are left out. A generated rail under the base hides the distal links' hinge lugs, so that open fingers hang from
   it rather than float beside the base.
4. The tripod column is the source's own box primitives, written as meshes on `base` and `torso`.
5. Write visuals.json, NOTICE.md and the license.
"""

from __future__ import annotations

import argparse
import io
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import common  # noqa: E402

REPOSITORY = "https://github.com/pollen-robotics/reachy2_mujoco"
COMMIT = "96f6c1d3497e0bdb9638e2e5d5df09dff8da253c"
LICENSE = "Apache-2.0"
PROJECT_LICENSE = "MIT (lerobot_tavis)"
MJCF = "reachy2_mujoco/description/mjcf/reachy2.xml"
OBJ_DIR = "reachy2_mujoco/description/mjcf/obj_meshes"
URDF_MESHES = "reachy2_mujoco/description/original_urdf"
DAE_PATHS = {
    "mobile_base_visual": "reachy_description/meshes/mobile_base_visual.dae",
    "torso_visual": "reachy_description/meshes/torso_visual.dae",
    "head_visual": "reachy_description/meshes/head_visual.dae",
    "head_antenna_visual": "reachy_description/meshes/head_antenna_visual.dae",
    "2D_sphere_visual": "orbita2d_description/meshes/2D_sphere_visual.dae",
    "upper_arm_visual": "reachy_description/meshes/upper_arm_visual.dae",
    "forearm_visual": "reachy_description/meshes/forearm_visual.dae",
    "pincette_base_visual": "dynamixel_description/meshes/pincette_base_visual.dae",
    "pincette_distal": "dynamixel_description/meshes/pincette_distal.dae",
}
OBJ_MISSING_FROM_MIRROR = {"upper_arm_visual"}
MAX_BYTES = 3_000_000  # the whole group

# Our materials (visuals.py manifest format). The real robot: white shells, dark grey joints and grippers, brushed
# aluminium tripod, black pads, eyes and antenna rods.
MATERIALS = {
    "shell": {"rgba": [0.92, 0.92, 0.93, 1.0], "specular": 0.35, "shininess": 0.5},
    "joint": {"rgba": [0.24, 0.25, 0.27, 1.0], "specular": 0.3, "shininess": 0.4},
    "metal": {"rgba": [0.66, 0.67, 0.69, 1.0], "specular": 0.5, "shininess": 0.6},
    "black": {"rgba": [0.06, 0.06, 0.07, 1.0], "specular": 0.4, "shininess": 0.6},
}


Box = tuple[tuple[float, float, float], tuple[float, float, float]]  # (min corner, max corner), m


@dataclass(frozen=True)
class Part:
    """One source visual mesh: its default material, its triangle budget per instance, and material overrides: for
    the connected pieces whose bounding box lies inside a region (mesh frame, first match wins), else by source
    colour (RGB 0-255, None = no material in the COLLADA file)."""

    mesh: str
    material: str
    triangles: int
    by_colour: tuple[tuple[tuple[int, int, int] | None, str], ...] = ()
    by_region: tuple[tuple[Box, str], ...] = ()


PARTS = {
    "mobile_base_visual": Part("mobile_base_visual", "shell", 1000),
    "torso_visual": Part("torso_visual", "shell", 2600, (((11, 55, 103), "joint"),)),
    "head_visual": Part("head_visual", "shell", 1500, by_region=(
        (((0.045, -0.05, 0.045), (0.07, 0.05, 0.08)), "black"),  # eye lenses, the bridge between them, ToF window
        (((0.03, -0.06, 0.035), (0.07, 0.06, 0.09)), "metal"),  # eye rims
        (((-0.03, -0.03, -0.01), (0.03, 0.03, 0.02)), "joint"),  # neck flange
    )),
    "head_antenna_visual": Part("head_antenna_visual", "black", 260, (((230, 230, 230), "shell"),
                                                                      ((233, 233, 233), "shell"),
                                                                      ((178, 178, 178), "metal"))),
    "2D_sphere_visual": Part("2D_sphere_visual", "joint", 500),
    "upper_arm_visual": Part("upper_arm_visual", "shell", 2200, (((178, 178, 178), "metal"), ((0, 0, 0), "black"),
                                                                 ((49, 112, 20), "black"))),
    "forearm_visual": Part("forearm_visual", "shell", 2200),
    "pincette_base_visual": Part("pincette_base_visual", "joint", 700),
    "pincette_distal": Part("pincette_distal", "joint", 450, (((14, 14, 14), "black"), ((178, 178, 178), "metal"))),
}

# Source body (reachy2.xml) -> our body. `{p}` is the arm prefix (l, r).
BODY_MAP = {
    "base_link": "base",
    "torso": "torso",
    "head": "head",
    "antenna_left_link": "head",  # the antennas' joints are not modelled: they stay at 0
    "antenna_right_link": "head",
    "{p}_shoulder_first_link": "{p}_shoulder_pitch_link",
    "{p}_elbow_arm_link": "{p}_shoulder_roll_link",
    "{p}_elbow_first_link": "{p}_elbow_yaw_link",
    "{p}_elbow_forearm_link": "{p}_elbow_pitch_link",
    "{p}_hand_palm_link": "{p}_hand",
}
# The distal finger links (two per hand) are placed on our slide fingers by `finger_shift`, not by the body map.
DISTAL_BODIES = ("{p}_hand_distal_link", "{p}_hand_distal_mimic_link")
# Tripod boxes drawn by the source (visual class); each side bar's inner box lies inside its outer one and is skipped.
TRIPOD_BOXES = {"back_bar_base": "base", "back_bar_inner": "base", "left_bar_base": "torso", "right_bar_base": "torso",
                "left_bar_anchor": "base", "right_bar_anchor": "base"}
SIDES = {"l": "left", "r": "right"}
WRAP_ALPHA_M = 0.003  # smallest opening kept open by the wrapping
WRAP_OFFSET_M = 0.0003  # how far the wrapped surface lies outside the source surface
MIN_PIECE_SHARE = 0.08  # each material piece of a part gets at least this share of its triangles
RAIL_DEPTH_M = 0.007  # the top of each distal link hidden in the rail
RAIL_INSET_M = 0.003  # the rail's top inside the pincette base
ALIGN_TOLERANCE_M = 1e-5
ALIGN_TOLERANCE_RAD = 1e-5


def expand(template: str) -> list[tuple[str, str]]:
    """(source body, our body) for both arms when the name holds `{p}`, else once."""
    if "{p}" not in template:
        return [(template, BODY_MAP[template])]
    return [(template.format(p=p), BODY_MAP[template].format(p=p)) for p in SIDES]


def body_map() -> dict[str, str]:
    return dict(pair for template in BODY_MAP for pair in expand(template))


# ---------------------------------------------------------------------------------------------------------- models

@dataclass(frozen=True)
class SourceGeom:
    """A visual geom of the source model: its body, mesh and pose in the body frame."""

    body: str
    mesh: str
    pos: np.ndarray
    quat: np.ndarray


def source_model(xml: str) -> tuple[mujoco.MjModel, list[SourceGeom], dict]:
    """The source MJCF compiled without its meshes (kinematics only), its visual mesh geoms, and the tripod's visual
    boxes ({body: (half sizes, pos, quat) in the body frame})."""
    spec = mujoco.MjSpec.from_string(xml)
    visual = [SourceGeom(g.parent.name, g.meshname, np.array(g.pos), np.array(g.quat)) for g in spec.geoms
              if g.type == mujoco.mjtGeom.mjGEOM_MESH and g.contype == 0 and g.conaffinity == 0]
    boxes = {g.parent.name: (np.array(g.size), np.array(g.pos), np.array(g.quat)) for g in spec.geoms
             if g.type == mujoco.mjtGeom.mjGEOM_BOX and g.contype == 0 and g.parent.name in TRIPOD_BOXES}
    for geom in [g for g in spec.geoms if g.type == mujoco.mjtGeom.mjGEOM_MESH]:
        spec.delete(geom)
    for mesh in list(spec.meshes):
        spec.delete(mesh)
    return spec.compile(), visual, boxes


def our_model() -> mujoco.MjModel:
    from lerobot_tavis.envs.robots.reachy2 import Reachy2

    return Reachy2().build_spec(dressed=False).compile()


def zero_pose_frames(model: mujoco.MjModel) -> mujoco.MjData:
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    return data


def relative_pose(src: tuple[mujoco.MjModel, mujoco.MjData], ours: tuple[mujoco.MjModel, mujoco.MjData],
                  source_body: str, our_body: str) -> tuple[np.ndarray, np.ndarray]:
    """Position (m) and rotation matrix of the source body in our body's frame."""
    (sm, sd), (om, od) = src, ours
    s, o = sm.body(source_body).id, om.body(our_body).id
    r_our = od.xmat[o].reshape(3, 3)
    return r_our.T @ (sd.xpos[s] - od.xpos[o]), r_our.T @ sd.xmat[s].reshape(3, 3)


def check_alignment(sm: mujoco.MjModel, om: mujoco.MjModel, seed: int = 0, trials: int = 5) -> tuple[float, float]:
    """Max position (m) and angle (rad) drift of the mapped bodies' relative poses at random arm and neck poses.

    Every hinge joint of ours exists in the source under the same name; both models get the same angle, drawn
    within our joint range (clipped to ±1.5 rad). Raises SystemExit when a body does not follow.
    """
    pairs = body_map()
    sd, od = zero_pose_frames(sm), zero_pose_frames(om)
    zero = {s: relative_pose((sm, sd), (om, od), s, o) for s, o in pairs.items()}
    rng = np.random.default_rng(seed)
    hinges = [j for j in range(om.njnt) if om.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    max_pos = max_ang = 0.0
    for _ in range(trials):
        for j in hinges:
            lo, hi = np.clip(om.jnt_range[j], -1.5, 1.5)
            angle = rng.uniform(lo, hi)
            od.qpos[om.jnt_qposadr[j]] = angle
            sd.qpos[sm.jnt_qposadr[sm.joint(om.joint(j).name).id]] = angle
        mujoco.mj_kinematics(sm, sd)
        mujoco.mj_kinematics(om, od)
        for s, o in pairs.items():
            pos, rot = relative_pose((sm, sd), (om, od), s, o)
            max_pos = max(max_pos, float(np.linalg.norm(pos - zero[s][0])))
            cos = (np.trace(rot.T @ zero[s][1]) - 1.0) / 2.0
            max_ang = max(max_ang, float(np.arccos(np.clip(cos, -1.0, 1.0))))
    if max_pos > ALIGN_TOLERANCE_M or max_ang > ALIGN_TOLERANCE_RAD:
        raise SystemExit(f"source bodies do not follow ours: drift {max_pos:.2e} m, {max_ang:.2e} rad")
    return max_pos, max_ang


# ---------------------------------------------------------------------------------------------------------- meshes

@dataclass
class Piece:
    """Triangles of one material, in some frame (metres)."""

    material: str
    vertices: np.ndarray
    faces: np.ndarray


def load_dae(data: bytes) -> list[tuple[tuple[int, int, int] | None, np.ndarray, np.ndarray]]:
    """The COLLADA scene's triangles grouped by material colour (RGB 0-255, None without material), node
    transforms applied, in the file's frame (metres: every source file declares meter=1, Z up)."""
    import trimesh

    scene = trimesh.load(io.BytesIO(data), file_type="dae", force="scene")
    groups: dict = {}
    for node in scene.graph.nodes_geometry:
        transform, name = scene.graph[node]
        geometry = scene.geometry[name]
        material = getattr(geometry.visual, "material", None)
        colour = None if material is None else tuple(int(c) for c in material.main_color[:3])
        verts = trimesh.transform_points(np.asarray(geometry.vertices, dtype=np.float64), transform)
        groups.setdefault(colour, []).append((verts, np.asarray(geometry.faces, dtype=np.int64)))
    out = []
    for colour, chunks in groups.items():
        offsets = np.cumsum([0] + [len(v) for v, _ in chunks])
        out.append((colour, np.concatenate([v for v, _ in chunks]),
                    np.concatenate([f + o for (_, f), o in zip(chunks, offsets)])))
    return out


def components(verts: np.ndarray, faces: np.ndarray) -> list:
    """Connected pieces (trimesh meshes) of a triangle set."""
    import trimesh

    return trimesh.Trimesh(verts, faces, process=False).split(only_watertight=False)


def region_material(part: Part, verts: np.ndarray) -> str | None:
    low, high = verts.min(0), verts.max(0)
    for (box_low, box_high), material in part.by_region:
        if np.all(low >= box_low) and np.all(high <= box_high):
            return material
    return None


def obj_bounds(data: bytes) -> np.ndarray:
    """(2, 3) bounding box of an OBJ file's vertices."""
    rows = [line.split()[1:4] for line in data.decode().splitlines() if line.startswith("v ")]
    verts = np.array(rows, dtype=np.float64)
    return np.stack([verts.min(0), verts.max(0)])


def source_pieces(repo: Path, part: Part) -> list[Piece]:
    """The part's triangles by our material, in its source geom frame; checked against the MJCF's OBJ."""
    pieces = load_dae(common.read_git_file(repo, COMMIT, f"{URDF_MESHES}/{DAE_PATHS[part.mesh]}"))
    if part.mesh not in OBJ_MISSING_FROM_MIRROR:
        every = np.concatenate([v for _, v, _ in pieces])
        expected = obj_bounds(common.read_git_file(repo, COMMIT, f"{OBJ_DIR}/{part.mesh}.obj"))
        if np.abs(np.stack([every.min(0), every.max(0)]) - expected).max() > 1e-6:
            raise SystemExit(f"{part.mesh}: the COLLADA file and the MJCF's OBJ differ")
    by_colour = dict(part.by_colour)
    merged: dict[str, list] = {}
    for colour, verts, faces in pieces:
        for component in components(verts, faces):
            material = region_material(part, component.vertices) or by_colour.get(colour, part.material)
            merged.setdefault(material, []).append((component.vertices, component.faces))
    return [concatenate([Piece(material, v, f) for v, f in chunks]) for material, chunks in sorted(merged.items())]


def concatenate(pieces: list[Piece]) -> Piece:
    """One piece of the pieces' triangles (the first one's material)."""
    offsets = np.cumsum([0] + [len(p.vertices) for p in pieces])
    return Piece(pieces[0].material, np.concatenate([p.vertices for p in pieces]),
                 np.concatenate([p.faces + k for p, k in zip(pieces, offsets)]))


def transform(pieces: list[Piece], rot: np.ndarray, pos: np.ndarray) -> list[Piece]:
    return [Piece(p.material, p.vertices @ rot.T + pos, p.faces) for p in pieces]


def quat_matrix(quat) -> np.ndarray:
    mat = np.zeros(9)
    mujoco.mju_quat2Mat(mat, np.asarray(quat, dtype=np.float64) / np.linalg.norm(quat))
    return mat.reshape(3, 3)


def wrap(piece: Piece, alpha_m: float = WRAP_ALPHA_M, offset_m: float = WRAP_OFFSET_M) -> Piece:
    """The piece's outer surface as one closed manifold (CGAL alpha wrapping through MeshLab).

    The CAD exports are soups of open patches, screws and hidden internals: decimated as they are, their borders
    either stall the collapse far above budget or fall apart into shards. Wrapping keeps what can be seen from
    outside (openings narrower than `alpha_m` are closed), inflated by `offset_m`, and decimates cleanly.
    """
    import pymeshlab

    diagonal = float(np.linalg.norm(piece.vertices.max(0) - piece.vertices.min(0)))
    mesh_set = pymeshlab.MeshSet()
    mesh_set.add_mesh(pymeshlab.Mesh(vertex_matrix=piece.vertices, face_matrix=piece.faces))
    mesh_set.generate_alpha_wrap(alpha=pymeshlab.PercentageValue(100 * alpha_m / diagonal),
                                 offset=pymeshlab.PercentageValue(100 * offset_m / diagonal))
    mesh = mesh_set.current_mesh()
    return Piece(piece.material, mesh.vertex_matrix(), mesh.face_matrix())


def simplify(pieces: list[Piece], triangles: int) -> list[Piece]:
    """Wrap each piece, then decimate: about `triangles` in all, shared among the pieces by their wrapped triangle
    counts, with at least MIN_PIECE_SHARE of them each (small coloured details, such as the eyes, stay round)."""
    wrapped = [wrap(p) for p in pieces]
    total = sum(len(p.faces) for p in wrapped)
    out = []
    for p in wrapped:
        target = round(triangles * max(MIN_PIECE_SHARE, len(p.faces) / total))
        verts, faces, _ = common.decimate(p.vertices, p.faces, target)
        out.append(Piece(p.material, np.asarray(verts), np.asarray(faces)))
    return out


def box_piece(material: str, half: np.ndarray, pos: np.ndarray, rot: np.ndarray) -> Piece:
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64) * half
    faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return Piece(material, corners @ rot.T + pos, faces)


# ---------------------------------------------------------------------------------------------------------- baking

@dataclass
class Baked:
    """An output mesh file and where the manifest puts it."""

    file: str
    body: str
    piece: Piece
    source_path: str
    changes: str
    quat: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)


def finger_shift(distal: list[Piece], om: mujoco.MjModel, od: mujoco.MjData, side: str) -> np.ndarray:
    """Translation (m) that puts finger a's distal link, given in the frame of finger a at its zero (closed)
    position, on its collision pad: tip on the pad's tip, inner face on the pad's inner face, centred on the pad
    across the finger (x)."""
    pad = om.geom(f"{side}_finger_a_pad")
    finger = pad.bodyid[0]
    r_finger = od.xmat[finger].reshape(3, 3)
    centre = r_finger.T @ (od.geom_xpos[pad.id] - od.xpos[finger])
    half = om.geom_size[pad.id]
    verts = np.concatenate([p.vertices for p in distal])
    return np.array([centre[0] - (verts[:, 0].min() + verts[:, 0].max()) / 2,
                     centre[1] - half[1] - verts[:, 1].min(),
                     centre[2] - half[2] - verts[:, 2].min()])


def rail(distal: list[Piece], base: Piece, om: mujoco.MjModel, side: str) -> Piece:
    """A bar under the pincette base (hand frame) that hides the top of the distal links (their hinge lugs): the
    slide fingers hang from it instead of floating beside the base when open. It reaches the middle of the lugs at
    full opening, so that it sticks out little beside closed fingers."""
    verts = np.concatenate([p.vertices for p in distal])
    lugs = verts[verts[:, 2] > verts[:, 2].max() - RAIL_DEPTH_M]
    half_stroke = om.jnt_range[om.joint(f"{side}_finger_a").id][1]
    top = base.vertices[:, 2].min() + RAIL_INSET_M
    bottom = lugs[:, 2].min()
    reach = half_stroke + (lugs[:, 1].min() + lugs[:, 1].max()) / 2
    half = np.array([np.abs(lugs[:, 0]).max(), reach, (top - bottom) / 2])
    return box_piece("joint", half, np.array([0.0, 0.0, (top + bottom) / 2]), np.eye(3))


class Baker:
    """Bakes source meshes into our bodies: both models at the zero pose, each source mesh simplified once."""

    def __init__(self, repo: Path, sm: mujoco.MjModel, om: mujoco.MjModel):
        self.repo, self.sm, self.om = repo, sm, om
        self.sd, self.od = zero_pose_frames(sm), zero_pose_frames(om)
        self._simplified: dict[str, list[Piece]] = {}

    def simplified(self, mesh: str) -> list[Piece]:
        """The mesh by material, simplified, in its source geom frame."""
        if mesh not in self._simplified:
            self._simplified[mesh] = simplify(source_pieces(self.repo, PARTS[mesh]), PARTS[mesh].triangles)
        return self._simplified[mesh]

    def into(self, pieces: list[Piece], source_body: str, our_body: str) -> list[Piece]:
        """Pieces given in a source body's frame, expressed in our body's frame."""
        s, o = self.sm.body(source_body).id, self.om.body(our_body).id
        pieces = transform(pieces, self.sd.xmat[s].reshape(3, 3), self.sd.xpos[s])
        r_our = self.od.xmat[o].reshape(3, 3)
        return transform(pieces, r_our.T, -r_our.T @ self.od.xpos[o])

    def geom_into(self, geom: SourceGeom, our_body: str) -> list[Piece]:
        pieces = transform(self.simplified(geom.mesh), quat_matrix(geom.quat), geom.pos)
        return self.into(pieces, geom.body, our_body)

    def mapped(self, visual: list[SourceGeom]) -> list[Baked]:
        """Every visual mesh of a BODY_MAP body, in its target body."""
        pairs = body_map()
        return [Baked(f"{pairs[g.body]}_{piece.material}.stl", pairs[g.body], piece, DAE_PATHS[g.mesh],
                      f"baked into body `{pairs[g.body]}`, split by material, alpha-wrapped, decimated")
                for g in visual if g.body in pairs for piece in self.geom_into(g, pairs[g.body])]

    def fingers(self, visual: list[SourceGeom], hand_base: dict[str, Piece]) -> list[Baked]:
        """Per hand: the distal link on both slide fingers (finger b: turned half a turn about z) and the rail."""
        baked = []
        for p, side in SIDES.items():
            # the source distal link on finger a's side (+y of our hand frame) at the source's zero pose
            candidates = [(g, self.geom_into(g, f"{side}_finger_a")) for g in visual
                          if g.body in {b.format(p=p) for b in DISTAL_BODIES}]
            geom, distal = max(candidates, key=lambda c: np.concatenate([d.vertices for d in c[1]])[:, 1].mean())
            distal = transform(distal, np.eye(3), finger_shift(distal, self.om, self.od, side))
            change = (f"distal link baked into `{side}_finger_a` (finger b: turned 180° about z), moved onto its pad, "
                      "split by material, alpha-wrapped, decimated")
            for piece in distal:
                file = f"{side}_finger_{piece.material}.stl"
                baked.append(Baked(file, f"{side}_finger_a", piece, DAE_PATHS[geom.mesh], change))
                baked.append(Baked(file, f"{side}_finger_b", piece, DAE_PATHS[geom.mesh], change, (0.0, 0.0, 0.0, 1.0)))
            baked.append(Baked(f"{p}_hand_joint.stl", f"{p}_hand", rail(distal, hand_base[p], self.om, side), "",
                               "plus a generated rail under the base that the sliding fingers hang from"))
        return baked

    def tripod(self, boxes: dict) -> list[Baked]:
        """The source's tripod boxes, one mesh per target body."""
        by_body: dict[str, list[Piece]] = {}
        for body, (half, pos, quat) in boxes.items():
            piece = box_piece("metal", half, pos, quat_matrix(quat))
            by_body.setdefault(TRIPOD_BOXES[body], []).extend(self.into([piece], body, TRIPOD_BOXES[body]))
        return [Baked(f"{body}_metal.stl", body, concatenate(pieces), MJCF,
                      f"the tripod's visual box primitives as a mesh in body `{body}`")
                for body, pieces in sorted(by_body.items())]


def bake(repo: Path, sm: mujoco.MjModel, visual: list[SourceGeom], boxes: dict, om: mujoco.MjModel) -> list[Baked]:
    baker = Baker(repo, sm, om)
    baked = baker.mapped(visual)
    hand_base = {p: next(b.piece for b in baked if b.body == f"{p}_hand") for p in SIDES}
    return baked + baker.fingers(visual, hand_base) + baker.tripod(boxes)


def merge_files(baked: list[Baked]) -> dict[str, Piece]:
    """One mesh per file name (pieces of one body and material are concatenated; a piece shared by two bodies once)."""
    files: dict[str, list[Piece]] = {}
    for b in baked:
        pieces = files.setdefault(b.file, [])
        if all(b.piece is not p for p in pieces):
            pieces.append(b.piece)
    return {name: concatenate(pieces) for name, pieces in files.items()}


def manifest(baked: list[Baked]) -> dict:
    meshes, seen = [], set()
    for b in baked:
        key = (b.file, b.body, b.quat)
        if key in seen:
            continue
        seen.add(key)
        entry = {"file": b.file, "body": b.body, "material": b.piece.material}
        if b.quat != (1.0, 0.0, 0.0, 0.0):
            entry["quat"] = list(b.quat)
        meshes.append(entry)
    return {"materials": MATERIALS, "meshes": meshes}


def manifest_text(data: dict) -> str:
    """JSON with one material or mesh entry per line."""
    materials = ",\n".join(f"  {json.dumps(k)}: {json.dumps(v)}" for k, v in data["materials"].items())
    meshes = ",\n".join(f"  {json.dumps(m)}" for m in data["meshes"])
    return f'{{"materials": {{\n{materials}\n }},\n "meshes": [\n{meshes}\n ]}}\n'


def provenance(baked: list[Baked]) -> list[common.Provenance]:
    """One NOTICE row per output file, naming every source file merged into it."""
    by_file: dict[str, list[Baked]] = {}
    for b in baked:
        by_file.setdefault(b.file, []).append(b)
    rows = []
    for file, parts in by_file.items():
        paths = list(dict.fromkeys(b.source_path if b.source_path == MJCF else f"{URDF_MESHES}/{b.source_path}"
                                   for b in parts if b.source_path))
        changes = "; ".join(dict.fromkeys(b.changes for b in parts))
        rows.append(common.Provenance(file, REPOSITORY, COMMIT, ", ".join(paths), LICENSE, changes))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--source", type=Path, required=True, help="clone or bare mirror of " + REPOSITORY)
    args = parser.parse_args()
    xml = common.read_git_file(args.source, COMMIT, MJCF).decode()
    sm, visual, boxes = source_model(xml)
    om = our_model()
    drift_m, drift_rad = check_alignment(sm, om)
    print(f"alignment: max drift {drift_m:.1e} m, {math.degrees(drift_rad):.1e} deg over random arm/neck poses")
    baked = bake(args.source, sm, visual, boxes, om)
    files = merge_files(baked)
    with common.staged_group("reachy2", MAX_BYTES) as staging:
        for name, piece in files.items():
            common.write_stl(staging / name, piece.vertices, piece.faces)
        (staging / "visuals.json").write_text(manifest_text(manifest(baked)))
        (staging / "LICENSE-reachy2_mujoco.txt").write_bytes(common.read_git_file(args.source, COMMIT, "LICENSE"))
        rows = provenance(baked) + [common.Provenance(
            "visuals.json", "this project", "", "", PROJECT_LICENSE,
            "generated by tools/assets/reachy2.py: which body carries each mesh, and the materials")]
        common.write_notice(staging, "Reachy 2 visual meshes",
                            "Pollen Robotics' Reachy 2 visual meshes (reachy2_mujoco, Apache-2.0, see "
                            "LICENSE-reachy2_mujoco.txt), baked into the body frames of lerobot_tavis's Reachy2 and "
                            "decimated by `tools/assets/reachy2.py`, which regenerates every file here.",
                            rows)
    triangles = sum(len(files[e["file"]].faces) for e in manifest(baked)["meshes"])
    print(f"{len(files)} meshes, {triangles} triangles drawn")


if __name__ == "__main__":
    main()
