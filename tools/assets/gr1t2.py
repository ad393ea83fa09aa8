"""Regenerate `lerobot_tavis/assets/gr1t2/`: the Fourier GR1T2's visual meshes and two Robotiq 2F-85 grippers,
baked into the bodies of our procedural GR1T2 (`lerobot_tavis/envs/robots/gr1t2.py`).

    python tools/assets/gr1t2.py --wheel fourier_robot_descriptions-0.2.7-py3-none-any.whl \
        --lerobot-mirror /path/to/huggingface/lerobot

`--wheel` is the PyPI wheel of fourier-robot-descriptions 0.2.7 (`pip download --no-deps
fourier-robot-descriptions==0.2.7`), checked by its sha256, or the folder it was unzipped into, checked file by file
against the wheel's RECORD (itself checked by sha256). `--lerobot-mirror` is a clone or bare mirror of
huggingface/lerobot holding commit `robotiq.COMMIT` (its franka_sim vendors MuJoCo Menagerie's Robotiq 2F-85).

1. The official URDF (`gr1t2.urdf`) is compiled in MuJoCo with its visual meshes. Each of our bodies stands for the
   URDF link that its joint moves (same joint names; `pelvis` = `base_link`, plus `torso_link`); the script checks
   that their frames coincide at the zero pose and at a random arm and neck pose, and stops if they do not.
2. Each link's mesh is baked into its body's frame at the zero pose. Legs, waist and IMU, which we do not simulate,
   go onto the static `pelvis`. The hands stop at `*_hand_pitch_link` (the URDF's Fourier hands are not used).
3. A few links are split by material (the head's visor, the hip handles), then every piece is cut to its triangle
   budget (`PIECES`) by `cad.simplify` and written as binary STL.
4. The top of the chest, which the head camera sees within the reference's 0.15 m near clip when the head pitches
   fully down, is bevelled out of that near view (`clear_head_view`).
5. Robotiq 2F-85 (`robotiq.py`): its base goes on each hand, with its pads' centre on our collision pads' centre.
   Our fingers translate where the real linkage turns, so each finger's whole linkage (driver, coupler, spring link,
   follower, pads) rides rigidly on our sliding finger body, posed as the real gripper is at the half-gap
   `GRIPPER_REFERENCE_HALF_GAP_M` (a typical grasp). The pads then coincide with our collision pads at every
   opening, and the linkage is exact at the reference gap and looks right from open to closed. Finger b carries the
   same meshes turned 180 degrees about the approach axis, as on the real gripper.
6. `visuals.json` (read by `lerobot_tavis/envs/robots/visuals.py`), NOTICE.md and the two licenses are written.
"""

from __future__ import annotations

import argparse
import base64
import hashlib
import io
import json
import re
import sys
import xml.etree.ElementTree as ET
import zipfile
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
import trimesh

sys.path.insert(0, str(Path(__file__).resolve().parent))
import cad  # noqa: E402
import robotiq  # noqa: E402
from common import Provenance, decimate, read_git_file, staged_group, write_notice, write_stl  # noqa: E402

from lerobot_tavis.envs.robots.gr1t2 import PELVIS_HEIGHT_M, GR1T2  # noqa: E402

WHEEL_NAME = "fourier_robot_descriptions-0.2.7-py3-none-any.whl"
WHEEL_SHA256 = "795fd084b94bd6058c187e327f3891259ae952be52e4d7c45d3c45ef96ec1885"
RECORD_PATH = "fourier_robot_descriptions-0.2.7.dist-info/RECORD"
RECORD_SHA256 = "0936102d6db00c60d282bcd2151747c7e1765432c19ee4a58a760b97c113d024"
URDF_PATH = "fourier_robot_descriptions/assets/urdf/gr1t2.urdf"
MESH_DIR = "fourier_robot_descriptions/assets/meshes/gr1t2"
WHEEL_LICENSE_PATH = "fourier_robot_descriptions-0.2.7.dist-info/licenses/LICENSE"
WHEEL_LICENSE = "Apache-2.0"
MAX_TRIANGLES = 25_000  # drawn by one robot: both arms, torso, head, legs and both grippers
MAX_BYTES = 3_000_000
FRAME_TOLERANCE_M = 1e-3  # our link positions may differ from the URDF's by rounding (0.25 mm at the torso)
FRAME_TOLERANCE_RAD = 1e-6
RANDOM_POSE_SEED = 20250601
GRIPPER_REFERENCE_HALF_GAP_M = 0.03  # linkage exact when each pad is 30 mm from the centre line (a 60 mm object)
FINGER_B_QUAT = (0.0, 0.0, 0.0, 1.0)  # 180 degrees about the hand's z (approach) axis
HEAD_NEAR_CLIP_M = 0.15  # the reference head camera's near clip (IsaacLab camera: clipping range 0.15-10 m)
HEAD_CLEAR_MARGIN_M = 0.01
NECK_SWEEP = {"pitch": (0.0, 0.87), "yaw": (-1.5, 1.5)}  # rad; poses whose near view the torso must keep out of

MATERIALS = {  # reference figure: dark gunmetal shells, lighter grey joints, black Robotiq with grey metal
    "shell": {"rgba": [0.24, 0.25, 0.27, 1.0], "specular": 0.5, "shininess": 0.6},
    "joint": {"rgba": [0.46, 0.47, 0.49, 1.0], "specular": 0.4, "shininess": 0.5},
    "visor": {"rgba": [0.02, 0.02, 0.025, 1.0], "specular": 0.9, "shininess": 0.9},
    "handle": {"rgba": [0.40, 0.32, 0.66, 1.0], "specular": 0.3, "shininess": 0.4},
    "robotiq_black": {"rgba": [0.08, 0.08, 0.09, 1.0], "specular": 0.4, "shininess": 0.4},
    "robotiq_metal": {"rgba": [0.52, 0.53, 0.55, 1.0], "specular": 0.7, "shininess": 0.7},
    "robotiq_pad": {"rgba": [0.14, 0.14, 0.15, 1.0], "specular": 0.1, "shininess": 0.1},
}


@dataclass(frozen=True)
class Region:
    """Connected parts of a link's mesh lying wholly inside an axis-aligned box (link frame, m) get `material`."""

    suffix: str
    material: str
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]


@dataclass(frozen=True)
class Piece:
    """One URDF link's visual mesh: its triangle budget and material (`regions` take parts of it elsewhere)."""

    link: str
    faces: int
    material: str
    regions: tuple[Region, ...] = ()


FAR = 1.0  # m, beyond any link's extent
VISOR = Region("visor", "visor", (0.065, -FAR, -FAR), (FAR, FAR, FAR))  # the face, wholly ahead of x = 65 mm
HANDLES = Region("handles", "handle", (-FAR, -FAR, 0.045), (FAR, FAR, FAR))  # the hip handles, above the hip motors


def _arm(side: str) -> list[Piece]:
    return [
        Piece(f"{side}_upper_arm_pitch_link", 400, "shell"),
        Piece(f"{side}_upper_arm_roll_link", 300, "joint"),
        Piece(f"{side}_upper_arm_yaw_link", 500, "shell"),
        Piece(f"{side}_lower_arm_pitch_link", 350, "joint"),
        Piece(f"{side}_hand_yaw_link", 650, "shell"),
        Piece(f"{side}_hand_roll_link", 60, "joint"),
        Piece(f"{side}_hand_pitch_link", 100, "joint"),  # mostly inside the Robotiq base
    ]


def _leg(side: str) -> list[Piece]:
    return [
        Piece(f"{side}_thigh_roll_link", 120, "joint"),
        Piece(f"{side}_thigh_yaw_link", 200, "joint"),
        Piece(f"{side}_thigh_pitch_link", 250, "shell"),
        Piece(f"{side}_shank_pitch_link", 220, "shell"),
        Piece(f"{side}_foot_pitch_link", 30, "joint"),
        Piece(f"{side}_foot_roll_link", 120, "shell"),
    ]


PIECES = [
    Piece("base_link", 800, "joint", (HANDLES,)),
    Piece("imu_link", 40, "joint"),
    Piece("waist_yaw_link", 150, "joint"),
    Piece("waist_pitch_link", 150, "joint"),
    Piece("waist_roll_link", 150, "joint"),
    Piece("torso_link", 1500, "shell"),
    Piece("head_roll_link", 100, "joint"),
    Piece("head_pitch_link", 150, "joint"),
    Piece("head_yaw_link", 1100, "shell", (VISOR,)),
    *_arm("left"), *_arm("right"), *_leg("left"), *_leg("right"),
]


@dataclass(frozen=True)
class GripperPart:
    """Robotiq meshes merged into one file: source meshes, triangle budget, material, and whether on the fingers."""

    file: str
    meshes: tuple[str, ...]
    faces: int
    material: str
    on_finger: bool


GRIPPER_PARTS = [
    GripperPart("robotiq_base.stl", ("base",), 900, "robotiq_black", on_finger=False),
    GripperPart("robotiq_driver.stl", ("driver",), 120, "robotiq_metal", on_finger=True),
    GripperPart("robotiq_links.stl", ("coupler", "spring_link", "follower"), 560, "robotiq_black", on_finger=True),
    GripperPart("robotiq_pad.stl", ("pad",), 40, "robotiq_metal", on_finger=True),
    GripperPart("robotiq_silicone_pad.stl", ("silicone_pad",), 40, "robotiq_pad", on_finger=True),
]


class Wheel:
    """Files of the fourier-robot-descriptions wheel, from the .whl or its unzipped folder, integrity-checked."""

    def __init__(self, path: Path):
        self.path = path
        if path.is_file():
            digest = hashlib.sha256(path.read_bytes()).hexdigest()
            if digest != WHEEL_SHA256:
                raise SystemExit(f"{path} has sha256 {digest}, expected {WHEEL_SHA256} ({WHEEL_NAME})")
            self._zip = zipfile.ZipFile(path)
            self._record = None
        elif path.is_dir():
            record = (path / RECORD_PATH).read_bytes()
            if hashlib.sha256(record).hexdigest() != RECORD_SHA256:
                raise SystemExit(f"{path / RECORD_PATH} is not the RECORD of {WHEEL_NAME}")
            self._zip = None
            self._record = {line.split(",")[0]: line.split(",")[1] for line in record.decode().splitlines() if line}
        else:
            raise SystemExit(f"--wheel {path} is neither {WHEEL_NAME} nor the folder it was unzipped into")

    def read(self, name: str) -> bytes:
        if self._zip is not None:
            return self._zip.read(name)
        data = (self.path / name).read_bytes()
        digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
        if self._record.get(name) != f"sha256={digest}":
            raise SystemExit(f"{self.path / name} differs from the file in {WHEEL_NAME}")
        return data


def urdf_visuals(urdf: str) -> dict[str, str]:
    """Mesh file name of each URDF link's visual, after checking that every visual sits at its link's origin."""
    meshes = {}
    for link in ET.fromstring(urdf).iter("link"):
        for visual in link.iter("visual"):
            origin = visual.find("origin")
            if origin is not None and any(float(v) for k in ("xyz", "rpy") for v in origin.get(k, "0 0 0").split()):
                raise SystemExit(f"URDF link {link.get('name')}: visual origin is not the identity")
            mesh = visual.find("geometry/mesh")
            if mesh.get("scale") not in (None, "1 1 1"):
                raise SystemExit(f"URDF link {link.get('name')}: scaled visual mesh")
            meshes[link.get("name")] = Path(mesh.get("filename")).name
    return meshes


def compile_urdf(wheel: Wheel, urdf: str) -> mujoco.MjModel:
    """The URDF as a MuJoCo model, meshes passed in memory, link bodies kept (no static fusion)."""
    xml = re.sub(r'filename="[^"]*/([^"/]+)"', r'filename="\1"', urdf)
    xml, found = re.subn(r"(<robot\b[^>]*>)",
                         r'\1<mujoco><compiler discardvisual="false" fusestatic="false"/></mujoco>', xml, count=1)
    if not found:
        raise SystemExit("the URDF has no <robot> element")
    assets = {name: wheel.read(f"{MESH_DIR}/{name}") for name in set(urdf_visuals(urdf).values())}
    return mujoco.MjModel.from_xml_string(xml, assets)


def body_for_link(urdf: mujoco.MjModel, ours: mujoco.MjModel) -> dict[str, str]:
    """Our body standing for each URDF link: the one moved by the same-named joint, else the static pelvis."""
    mapping = {"base_link": "pelvis", "torso_link": "torso_link"}
    for joint in range(ours.njnt):
        if ours.jnt_type[joint] != mujoco.mjtJoint.mjJNT_HINGE:
            continue
        name = ours.joint(joint).name
        mapping[urdf.body(urdf.jnt_bodyid[urdf.joint(name).id]).name] = ours.body(ours.jnt_bodyid[joint]).name
    return mapping


def check_frames(urdf: mujoco.MjModel, ours: mujoco.MjModel, mapping: dict[str, str]) -> dict[str, float]:
    """Largest position (m) and angle (rad) gaps between mapped frames, at the zero pose and a random pose."""
    rng = np.random.default_rng(RANDOM_POSE_SEED)
    worst = {"zero_m": 0.0, "zero_rad": 0.0, "random_m": 0.0, "random_rad": 0.0}
    for pose in ("zero", "random"):
        urdf_data, our_data = mujoco.MjData(urdf), mujoco.MjData(ours)
        if pose == "random":
            for joint in range(ours.njnt):
                if ours.jnt_type[joint] == mujoco.mjtJoint.mjJNT_HINGE:
                    value = rng.uniform(*ours.jnt_range[joint])
                    our_data.qpos[ours.jnt_qposadr[joint]] = value
                    urdf_data.qpos[urdf.jnt_qposadr[urdf.joint(ours.joint(joint).name).id]] = value
        mujoco.mj_kinematics(urdf, urdf_data)
        mujoco.mj_kinematics(ours, our_data)
        for link, body in mapping.items():
            if body == "pelvis" and link != "base_link":
                continue  # legs and waist: not simulated, checked through base_link only
            u, o = urdf.body(link).id, ours.body(body).id
            gap_m = np.linalg.norm(urdf_data.xpos[u] + (0, 0, PELVIS_HEIGHT_M) - our_data.xpos[o])
            gap_rad = 2 * np.arccos(min(1.0, abs(float(np.dot(urdf_data.xquat[u], our_data.xquat[o])))))
            worst[f"{pose}_m"] = max(worst[f"{pose}_m"], gap_m)
            worst[f"{pose}_rad"] = max(worst[f"{pose}_rad"], gap_rad)
            if gap_m > FRAME_TOLERANCE_M or gap_rad > FRAME_TOLERANCE_RAD:
                raise SystemExit(f"{pose} pose: URDF link {link} and our body {body} differ by "
                                 f"{gap_m * 1000:.2f} mm, {np.degrees(gap_rad):.4f} deg")
    return worst


def load_stl(data: bytes) -> tuple[np.ndarray, np.ndarray]:
    mesh = trimesh.load(io.BytesIO(data), file_type="stl")
    return np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces)


def head_camera_poses(ours: mujoco.MjModel) -> list[tuple[np.ndarray, np.ndarray]]:
    """(rotation, position) of the head camera in the torso frame over `NECK_SWEEP` (roll 0, as in teleoperation)."""
    data = mujoco.MjData(ours)
    camera, torso = ours.camera("head").id, ours.body("torso_link").id
    poses = []
    for pitch in np.linspace(*NECK_SWEEP["pitch"], 12):
        for yaw in np.linspace(*NECK_SWEEP["yaw"], 31):
            data.qpos[ours.jnt_qposadr[ours.joint("head_pitch_joint").id]] = pitch
            data.qpos[ours.jnt_qposadr[ours.joint("head_yaw_joint").id]] = yaw
            mujoco.mj_kinematics(ours, data)
            mujoco.mj_camlight(ours, data)
            torso_rot = data.xmat[torso].reshape(3, 3)
            poses.append((torso_rot.T @ data.cam_xmat[camera].reshape(3, 3),
                          torso_rot.T @ (data.cam_xpos[camera] - data.xpos[torso])))
    return poses


def in_head_view(points: np.ndarray, poses, half_tan: tuple[float, float], reach_m: float) -> np.ndarray:
    """Points (torso frame) that some head camera pose sees closer than `reach_m` (inside the view pyramid)."""
    hit = np.zeros(len(points), dtype=bool)
    for rotation, position in poses:
        local = (points - position) @ rotation  # camera frame: x right, y up, looking along -z
        depth = -local[:, 2]
        in_pyramid = (np.abs(local[:, 0]) <= half_tan[0] * depth) & (np.abs(local[:, 1]) <= half_tan[1] * depth)
        hit |= (depth > 0) & in_pyramid & (np.linalg.norm(local, axis=1) < reach_m)
    return hit


def clear_head_view(vertices: np.ndarray, ours: mujoco.MjModel) -> tuple[np.ndarray, int]:
    """Torso-frame vertices with those the head camera would see within its near clip pushed down out of view.

    The reference renders its head camera with a 0.15 m near clip, so the top of the chest, which the lens sees when
    the head pitches fully down, never shows there; we bevel it away instead. Returns the vertices and how many moved.
    """
    poses = head_camera_poses(ours)
    vfov = np.radians(ours.cam_fovy[ours.camera("head").id])
    half_tan = (np.tan(vfov / 2) * 640 / 480, np.tan(vfov / 2))
    reach = HEAD_NEAR_CLIP_M + HEAD_CLEAR_MARGIN_M
    vertices = vertices.copy()
    moved = in_head_view(vertices, poses, half_tan, reach)
    todo = moved.copy()
    while todo.any():
        vertices[todo, 2] -= 0.001
        todo[todo] = in_head_view(vertices[todo], poses, half_tan, reach)
    return vertices, int(moved.sum())


def region_masks(vertices: np.ndarray, faces: np.ndarray, regions: tuple[Region, ...]) -> list[np.ndarray]:
    """For each region, the faces of the connected parts lying wholly inside its box (first region wins)."""
    adjacency = trimesh.graph.face_adjacency(faces)
    labels = trimesh.graph.connected_component_labels(adjacency, node_count=len(faces))
    masks, taken = [], np.zeros(len(faces), dtype=bool)
    for region in regions:
        mask = np.zeros(len(faces), dtype=bool)
        for label in np.unique(labels):
            part = labels == label
            corners = vertices[faces[part]].reshape(-1, 3)
            if np.all(corners.min(axis=0) >= region.lo) and np.all(corners.max(axis=0) <= region.hi):
                mask |= part
        mask &= ~taken
        taken |= mask
        masks.append(mask)
    return masks


@dataclass
class Output:
    """One written mesh file and where the manifest puts it."""

    file: str
    material: str
    bodies: list[tuple[str, tuple[float, ...]]]  # (body, quat) of each instance
    faces: int
    provenance: Provenance


def bake_links(wheel: Wheel, urdf_text: str, urdf: mujoco.MjModel, ours: mujoco.MjModel,
               mapping: dict[str, str], staging: Path) -> list[Output]:
    """Every `PIECES` link mesh in its body's frame (zero pose), split by region, simplified, written as STL."""
    visuals = urdf_visuals(urdf_text)
    urdf_data, our_data = mujoco.MjData(urdf), mujoco.MjData(ours)
    mujoco.mj_kinematics(urdf, urdf_data)
    mujoco.mj_kinematics(ours, our_data)
    outputs = []
    for piece in PIECES:
        body = mapping.get(piece.link, "pelvis")
        source = f"{MESH_DIR}/{visuals[piece.link]}"
        vertices, faces = load_stl(wheel.read(source))
        link, target = urdf.body(piece.link).id, ours.body(body).id
        link_rot, body_rot = urdf_data.xmat[link].reshape(3, 3), our_data.xmat[target].reshape(3, 3)
        world = vertices @ link_rot.T + urdf_data.xpos[link] + (0, 0, PELVIS_HEIGHT_M)
        baked = (world - our_data.xpos[target]) @ body_rot
        if body == "torso_link":
            baked, moved = clear_head_view(baked, ours)
            print(f"{piece.link}: {moved} vertices pushed out of the head camera's near view")
        masks = region_masks(vertices, faces, piece.regions) if piece.regions else []
        rest = np.ones(len(faces), dtype=bool)
        for mask in masks:
            rest &= ~mask
        groups = [("", piece.material, rest)] + [(f"_{r.suffix}", r.material, m) for r, m in zip(piece.regions, masks)]
        for suffix, material, mask in groups:
            if not mask.any():
                raise SystemExit(f"{piece.link}: region {suffix or 'rest'} selects no triangle")
            budget = max(cad.MIN_PART_FACES, round(piece.faces * mask.sum() / len(faces)))
            out_vertices, out_faces, summary = cad.simplify(baked, faces[mask], budget)
            if body == "torso_link":
                out_vertices, _ = clear_head_view(out_vertices, ours)
                summary += "; the chest top bevelled out of the head camera's near view"
            name = f"{piece.link}{suffix}.stl"
            write_stl(staging / name, out_vertices, out_faces)
            where = f"`{body}`" + (" at the zero pose" if body == "pelvis" and piece.link != "base_link" else "")
            others = ", ".join(r.suffix for r in piece.regions)
            part = f"its {suffix[1:]}" if suffix else (f"all but its {others}" if others else "the whole mesh")
            changes = f"{part}, baked into our body {where}; {summary}; binary STL"
            outputs.append(Output(name, material, [(body, (1.0, 0.0, 0.0, 0.0))], len(out_faces),
                                  Provenance(name, PYPI_SOURCE, WHEEL_SHA256, source, WHEEL_LICENSE, changes)))
            print(f"{name}: {mask.sum()} -> {len(out_faces)} triangles on {body}")
    return outputs


def finger_pad(ours: mujoco.MjModel, side: str) -> tuple[float, float]:
    """Our finger a's collision pad in its body frame: y of its gripping face and z of its centre (m)."""
    pad = ours.geom(f"{side}_finger_a_pad").id
    return float(ours.geom_pos[pad][1] - ours.geom_size[pad][1]), float(ours.geom_pos[pad][2])


def bake_gripper(mirror: Path, ours: mujoco.MjModel, staging: Path) -> list[Output]:
    """The 2F-85's base on both hands and its finger linkage on all four sliding fingers (see the module doc)."""
    model = robotiq.load(mirror)
    closing = robotiq.closing_for_gap(model, GRIPPER_REFERENCE_HALF_GAP_M)
    parts = robotiq.posed_parts(model, closing)
    (silicone,) = [p for p in parts if p.body == "right_silicone_pad"]
    face_y, pad_z = finger_pad(ours, "left")
    if finger_pad(ours, "right") != (face_y, pad_z):
        raise SystemExit("the left and right grippers differ: one Robotiq bake cannot serve both")
    # gripper frame -> hand frame: approach +z becomes the hand's -z, the right finger stays on +y, and the gripper
    # origin sits where the pads' centre at the reference gap lands on our collision pads' centre
    origin_z = pad_z + (silicone.vertices[:, 2].min() + silicone.vertices[:, 2].max()) / 2
    to_hand = np.diag([-1.0, 1.0, -1.0])
    finger_shift = np.array([0.0, face_y - robotiq.inner_pad_face_y(model, closing), 0.0])
    outputs = []
    for spec in GRIPPER_PARTS:
        chosen = [p for p in parts if p.mesh in spec.meshes and (p.body.startswith("right_") or not spec.on_finger)]
        vertices, faces, offset = [], [], 0
        for part in chosen:
            vertices.append(part.vertices @ to_hand.T + (0.0, 0.0, origin_z))
            faces.append(part.faces + offset)
            offset += len(part.vertices)
        vertices, faces = np.concatenate(vertices), np.concatenate(faces)
        if spec.on_finger:
            vertices = vertices + finger_shift
            bodies = [(f"{side}_finger_{f}", quat) for side in GR1T2.SIDES
                      for f, quat in (("a", (1.0, 0.0, 0.0, 0.0)), ("b", FINGER_B_QUAT))]
            where = ("each sliding finger (finger b turned 180 deg about the approach axis), posed as the real "
                     f"linkage at a {2 * GRIPPER_REFERENCE_HALF_GAP_M * 1000:.0f} mm gap")
        else:
            bodies = [(f"{side}_hand_pitch_link", (1.0, 0.0, 0.0, 0.0)) for side in GR1T2.SIDES]
            where = (f"each hand, its mounting face {origin_z * 1000:.1f} mm above the wrist centre so that the pads' "
                     f"centre at the {2 * GRIPPER_REFERENCE_HALF_GAP_M * 1000:.0f} mm reference gap is on our "
                     "collision pads' centre")
        out_vertices, out_faces, _ = decimate(vertices, faces, spec.faces)
        write_stl(staging / spec.file, out_vertices, out_faces)
        sources = ", ".join(robotiq.source_path(f"assets/{m}.stl") for m in spec.meshes)
        merged = f"{' + '.join(spec.meshes)} merged, " if len(spec.meshes) > 1 else ""
        changes = (f"{merged}scaled mm -> m, placed on {where}; decimated "
                   f"{len(faces):,} -> {len(out_faces):,} triangles, binary STL")
        outputs.append(Output(spec.file, spec.material, bodies, len(out_faces),
                              Provenance(spec.file, robotiq.REPOSITORY, robotiq.COMMIT, sources,
                                         robotiq.LICENSE, changes)))
        print(f"{spec.file}: {len(faces)} -> {len(out_faces)} triangles on {len(bodies)} bodies")
    return outputs


def write_manifest(staging: Path, outputs: list[Output]) -> None:
    meshes = [{"file": o.file, "body": body, "material": o.material, "pos": [0.0, 0.0, 0.0], "quat": list(quat)}
              for o in outputs for body, quat in o.bodies]
    (staging / "visuals.json").write_text(json.dumps({"materials": MATERIALS, "meshes": meshes}, indent=1) + "\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--wheel", type=Path, required=True, help=f"{WHEEL_NAME} or its unzipped folder")
    parser.add_argument("--lerobot-mirror", type=Path, required=True,
                        help="clone or bare mirror of huggingface/lerobot")
    args = parser.parse_args()
    wheel = Wheel(args.wheel)
    urdf_text = wheel.read(URDF_PATH).decode()
    urdf = compile_urdf(wheel, urdf_text)
    ours = GR1T2().build_spec().compile()
    mapping = body_for_link(urdf, ours)
    worst = check_frames(urdf, ours, mapping)
    print("URDF frames vs ours: " + ", ".join(
        f"{k} {v * 1000:.2f} mm" if k.endswith("_m") else f"{k} {np.degrees(v):.1e} deg" for k, v in worst.items()))
    missing = set(urdf_visuals(urdf_text)) ^ {p.link for p in PIECES}
    if missing:
        raise SystemExit(f"URDF links with a visual and `PIECES` must match; they differ by {sorted(missing)}")

    with staged_group("gr1t2", MAX_BYTES) as staging:
        outputs = bake_links(wheel, urdf_text, urdf, ours, mapping, staging)
        outputs += bake_gripper(args.lerobot_mirror, ours, staging)
        triangles = sum(o.faces * len(o.bodies) for o in outputs)
        if triangles > MAX_TRIANGLES:
            raise SystemExit(f"the dressed GR1T2 draws {triangles:,} triangles, over the {MAX_TRIANGLES:,} budget")
        write_manifest(staging, outputs)
        (staging / "LICENSE-fourier-robot-descriptions.txt").write_bytes(wheel.read(WHEEL_LICENSE_PATH))
        (staging / "LICENSE-robotiq_2f85.txt").write_bytes(
            read_git_file(args.lerobot_mirror, robotiq.COMMIT, robotiq.source_path("LICENSE")))
        write_notice(staging, "GR1T2 with Robotiq 2F-85 grippers", INTRO, [o.provenance for o in outputs])
    print(f"{triangles:,} triangles drawn")


PYPI_SOURCE = f"PyPI `fourier-robot-descriptions` 0.2.7 (`{WHEEL_NAME}`)"
INTRO = f"""\
Visual meshes of the Fourier GR1T2 humanoid and of the Robotiq 2F-85 gripper, baked into the bodies of our
procedural GR1T2 (`lerobot_tavis/envs/robots/gr1t2.py`) and listed with their materials in `visuals.json`.

* GR1T2: the STL meshes of the official URDF `{URDF_PATH}` in the PyPI wheel
  `{WHEEL_NAME}`, sha256 `{WHEEL_SHA256}` (the commit column
  shows its first 12 hex digits), by Fourier Intelligence, Apache-2.0 (`LICENSE-fourier-robot-descriptions.txt`).
* Robotiq 2F-85: MuJoCo Menagerie's `robotiq_2f85` model (derived from ROS-Industrial's Robotiq description),
  BSD-2-Clause (`LICENSE-robotiq_2f85.txt`), as vendored unmodified in huggingface/lerobot.

The meshes were changed as the table says: moved into our body frames, split by material, merged, simplified and
written as binary STL. Regenerate them with
`python tools/assets/gr1t2.py --wheel {WHEEL_NAME} --lerobot-mirror <huggingface/lerobot clone>`."""

if __name__ == "__main__":
    main()
