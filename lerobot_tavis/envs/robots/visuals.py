"""Dress a procedural robot in its real shape: vendored visual meshes replace the primitives on screen.

`assets/<robot>/visuals.json` lists the materials and, for each mesh, the robot body that carries it, with its pose
in that body's frame (`tools/assets/` bakes the source model's link offsets into the vertices, so the pose is
usually the identity):

    {"materials": {"shell": {"rgba": [0.9, 0.9, 0.9, 1], "specular": 0.4, "shininess": 0.5}},
     "meshes": [{"file": "left_upper_arm.stl", "body": "left_shoulder_yaw_link", "material": "shell",
                 "pos": [0, 0, 0], "quat": [1, 0, 0, 0]}]}

Dressing changes only what is drawn: primitives that collide stay, hidden in the collision group; look-only
primitives are removed. Masses, inertias, contacts, kinematics and control stay exactly as before.
"""

from __future__ import annotations

import json
from pathlib import Path

import mujoco

from lerobot_tavis.envs import assets, physics


def dress(spec: mujoco.MjSpec, asset_group: str) -> None:
    """Replace the drawn primitives of the robot in `spec` by the meshes of `assets/<asset_group>/visuals.json`."""
    manifest = json.loads(Path(assets.asset_file(f"{asset_group}/visuals.json")).read_text())
    for geom in list(spec.geoms):
        if geom.contype or geom.conaffinity:
            geom.group = physics.GROUP_HIDDEN
        else:
            spec.delete(geom)
    for name, material in manifest["materials"].items():
        assets.add_material(spec, name, **material)
    meshes = set()
    for i, entry in enumerate(manifest["meshes"]):
        mesh = Path(entry["file"]).stem
        if mesh not in meshes:
            assets.add_mesh(spec, mesh, f"{asset_group}/{entry['file']}")
            meshes.add(mesh)
        body = spec.body(entry["body"])
        if body is None:
            raise ValueError(f"{asset_group}/visuals.json entry {i} names body {entry['body']!r}, which the robot "
                             "model does not have")
        assets.add_visual_mesh(body, f"{entry['body']}/visual{i}", mesh, entry["material"],
                               pos=entry.get("pos", (0.0, 0.0, 0.0)), quat=entry.get("quat", (1.0, 0.0, 0.0, 0.0)))
