"""Shared steps of the asset scripts: read a source file at a pinned commit, decimate, write meshes and textures,
and record where every file came from.

Sources are local git clones (or `fetch` mirrors) checked at the commit named in each script; the scripts never
download anything. Meshes are written in metres, in the frame of the body or object that carries them.
"""

from __future__ import annotations

import shutil
import struct
import subprocess
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

PACKAGE_ASSETS = Path(__file__).resolve().parents[2] / "lerobot_tavis" / "assets"
MAX_TEXTURE_PX = 1024


def read_git_file(repo: Path, commit: str, path: str) -> bytes:
    """The bytes of `path` at `commit` in the git repository `repo` (a clone or a bare mirror)."""
    result = subprocess.run(["git", "-C", str(repo), "show", f"{commit}:{path}"], capture_output=True)
    if result.returncode != 0:
        raise SystemExit(f"cannot read {path} at {commit} in {repo}: {result.stderr.decode().strip()}")
    return result.stdout


@contextmanager
def staged_group(group: str, max_bytes: int) -> Iterator[Path]:
    """A fresh staging folder for the asset group `group`. When the block ends without error and the folder holds at
    most `max_bytes`, it replaces `lerobot_tavis/assets/<group>` whole; otherwise the packaged group is left as it
    was. The staging folder never outlives the block."""
    out_dir = PACKAGE_ASSETS / group
    staging = PACKAGE_ASSETS / f".{group}.staging"
    shutil.rmtree(staging, ignore_errors=True)
    staging.mkdir(parents=True)
    try:
        yield staging
        total = sum(path.stat().st_size for path in staging.iterdir())
        if total > max_bytes:
            raise SystemExit(f"the {group} assets take {total / 1e6:.2f} MB, over the {max_bytes / 1e6:.1f} MB budget")
        shutil.rmtree(out_dir, ignore_errors=True)
        staging.rename(out_dir)
        print(f"wrote {out_dir} ({total / 1e6:.2f} MB)")
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def decimate(vertices: np.ndarray, faces: np.ndarray, target_faces: int, vertex_uv: np.ndarray | None = None):
    """Quadric edge-collapse decimation (MeshLab) to about `target_faces` triangles.

    Returns (vertices, faces, wedge_uv): wedge_uv is (F, 3, 2) texture coordinates per face corner when
    `vertex_uv` (V, 2) was given, else None. Meshes already under the target are returned unchanged.
    """
    import pymeshlab

    if len(faces) <= target_faces:
        wedge = None if vertex_uv is None else vertex_uv[faces]
        return vertices, faces, wedge
    mesh_set = pymeshlab.MeshSet()
    if vertex_uv is None:
        mesh_set.add_mesh(pymeshlab.Mesh(vertex_matrix=vertices.astype(np.float64), face_matrix=faces))
        mesh_set.meshing_remove_duplicate_vertices()
        mesh_set.meshing_decimation_quadric_edge_collapse(targetfacenum=target_faces, preservenormal=True,
                                                          preserveboundary=True, qualitythr=0.5)
    else:
        mesh_set.add_mesh(pymeshlab.Mesh(vertex_matrix=vertices.astype(np.float64), face_matrix=faces,
                                         v_tex_coords_matrix=vertex_uv.astype(np.float64)))
        mesh_set.compute_texcoord_transfer_vertex_to_wedge()
        # Per-vertex coordinates split vertices along texture seams; merged, the seams become wedge discontinuities
        # that the texture-aware collapse respects, instead of open borders that it cannot simplify.
        mesh_set.meshing_remove_duplicate_vertices()
        mesh_set.meshing_decimation_quadric_edge_collapse_with_texture(targetfacenum=target_faces,
                                                                       preserveboundary=True, qualitythr=0.5)
    mesh = mesh_set.current_mesh()
    out_faces = mesh.face_matrix()
    wedge = None if vertex_uv is None else mesh.wedge_tex_coord_matrix().reshape(len(out_faces), 3, 2)
    return mesh.vertex_matrix(), out_faces, wedge


def write_stl(path: Path, vertices: np.ndarray, faces: np.ndarray) -> None:
    """Binary STL (MuJoCo's compact mesh format without texture coordinates)."""
    tri = vertices[faces].astype(np.float32)
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)
    records = np.zeros(len(faces), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    records["n"], records["v"] = normals, tri
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "wb") as stream:
        stream.write(b"lerobot_tavis visual mesh".ljust(80, b" "))
        stream.write(struct.pack("<I", len(faces)))
        stream.write(records.tobytes())


def write_obj(path: Path, vertices: np.ndarray, faces: np.ndarray, wedge_uv: np.ndarray) -> None:
    """Wavefront OBJ with per-corner texture coordinates (identical coordinates are shared)."""
    uv, uv_index = np.unique(np.round(wedge_uv.reshape(-1, 2), 6), axis=0, return_inverse=True)
    uv_index = uv_index.reshape(-1, 3)
    lines = [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in vertices]
    lines += [f"vt {u:.6f} {v:.6f}" for u, v in uv]
    lines += [f"f {a + 1}/{ta + 1} {b + 1}/{tb + 1} {c + 1}/{tc + 1}"
              for (a, b, c), (ta, tb, tc) in zip(faces, uv_index)]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")


def write_texture(path: Path, rgb: np.ndarray, max_px: int = MAX_TEXTURE_PX) -> None:
    """PNG of an (H, W, 3) uint8 RGB image, shrunk (area filter) so that its longer side is at most `max_px`."""
    scale = max_px / max(rgb.shape[:2])
    if scale < 1:
        rgb = cv2.resize(rgb, (round(rgb.shape[1] * scale), round(rgb.shape[0] * scale)),
                         interpolation=cv2.INTER_AREA)
    path.parent.mkdir(parents=True, exist_ok=True)
    if not cv2.imwrite(str(path), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_PNG_COMPRESSION, 9]):
        raise SystemExit(f"could not write {path}")


@dataclass(frozen=True)
class Provenance:
    """Where a vendored file came from. `source_path` is empty for files this project generated itself."""

    file: str
    repository: str
    commit: str
    source_path: str
    license: str
    changes: str


def write_notice(directory: Path, title: str, intro: str, entries: list[Provenance]) -> None:
    """NOTICE.md beside the files of one asset group: one row per file."""
    rows = [f"| `{e.file}` | {e.repository} | `{e.commit[:12]}` | `{e.source_path}` | {e.license} | {e.changes} |"
            for e in sorted(entries, key=lambda e: e.file)]
    text = "\n".join([f"# {title}", "", intro, "",
                      "| file | source repository | commit | source file | license | changes |",
                      "|---|---|---|---|---|---|", *rows, ""])
    (directory / "NOTICE.md").write_text(text)
