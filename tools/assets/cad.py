"""Low-polygon look-alikes of CAD exports: robot meshes made of hundreds of overlapping parts with thin walls and
sliver triangles, which plain edge collapse shreds at a few hundred triangles.

`simplify` keeps the parts with the most visible surface and gives each a share of the triangle budget: a part that
its convex hull follows closely (a cover, a motor) becomes its decimated hull, solid and smooth at any budget; any
other part (a handle, a bracket) is remeshed into even triangles and then decimated. Vertices in metres, any frame.
"""

from __future__ import annotations

import numpy as np
import pymeshlab
import trimesh
from common import decimate

VISIBILITY_RAYS = 128
SAMPLING_SEED = 7
MIN_PART_FACES = 10
HULL_TOLERANCE = 0.05  # mean hull-to-part distance, as a fraction of the part's bounding-box diagonal
REMESH_MIN_EDGE_M = 0.002
REMESH_OVERSAMPLING = 2.0  # remeshed triangles per budgeted triangle, before the collapse


def visible_faces(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Faces with a corner seen from outside the mesh (MeshLab ambient occlusion over `VISIBILITY_RAYS` directions)."""
    mesh_set = pymeshlab.MeshSet()
    mesh_set.add_mesh(pymeshlab.Mesh(vertex_matrix=vertices, face_matrix=faces))
    mesh_set.compute_scalar_ambient_occlusion(rays=VISIBILITY_RAYS)
    return (mesh_set.current_mesh().vertex_scalar_array()[faces] > 0).any(axis=1)


def surface_samples(mesh: trimesh.Trimesh, count: int) -> np.ndarray:
    points, _ = trimesh.sample.sample_surface(mesh, count, seed=SAMPLING_SEED)
    return points


def mean_gap_m(points: np.ndarray, reference: np.ndarray) -> float:
    """Mean distance from each point to its nearest reference point (m)."""
    nearest = [np.sqrt(((chunk[:, None] - reference[None]) ** 2).sum(-1).min(axis=1))
               for chunk in np.array_split(points, max(1, len(points) // 256))]
    return float(np.concatenate(nearest).mean())


def remesh_and_decimate(vertices: np.ndarray, faces: np.ndarray, target_faces: int) -> tuple[np.ndarray, np.ndarray]:
    """Isotropic remeshing (even triangles, so that the collapse keeps the shape) then quadric decimation."""
    area = trimesh.Trimesh(vertices, faces, process=False).area
    mesh_set = pymeshlab.MeshSet()
    mesh_set.add_mesh(pymeshlab.Mesh(vertex_matrix=vertices, face_matrix=faces))
    mesh_set.meshing_remove_duplicate_vertices()
    edge = max(REMESH_MIN_EDGE_M, float(np.sqrt(area / (REMESH_OVERSAMPLING * target_faces))))
    mesh_set.meshing_isotropic_explicit_remeshing(targetlen=pymeshlab.PureValue(edge), iterations=4)
    mesh = mesh_set.current_mesh()
    return decimate(mesh.vertex_matrix(), mesh.face_matrix(), target_faces)[:2]


def simplify(vertices: np.ndarray, faces: np.ndarray, target_faces: int) -> tuple[np.ndarray, np.ndarray, str]:
    """About `target_faces` triangles that look like the mesh; also a one-line account of what was done.

    Parts (connected sets of triangles) are ranked by visible area; a part is kept while its share of the budget,
    proportional to that area, is at least `MIN_PART_FACES`.
    """
    welded = trimesh.Trimesh(vertices, faces)
    vertices, faces = np.asarray(welded.vertices, dtype=float), np.asarray(welded.faces)
    corners = vertices[faces]
    area = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    labels = trimesh.graph.connected_component_labels(trimesh.graph.face_adjacency(faces), node_count=len(faces))
    seen_area = np.bincount(labels, weights=area * visible_faces(vertices, faces), minlength=labels.max() + 1)
    kept, total = [], 0.0
    for part in np.argsort(-seen_area, kind="stable"):
        if seen_area[part] == 0 or target_faces * seen_area[part] / (total + seen_area[part]) < MIN_PART_FACES:
            break
        kept.append(part)
        total += seen_area[part]
    out_vertices, out_faces, count, hulls = [], [], 0, 0
    for part in kept:
        mesh = trimesh.Trimesh(vertices, faces[labels == part], process=False)
        mesh.remove_unreferenced_vertices()
        budget = max(MIN_PART_FACES, round(target_faces * seen_area[part] / total))
        hull = mesh.convex_hull
        if mean_gap_m(surface_samples(hull, 1500), surface_samples(mesh, 3000)) <= HULL_TOLERANCE * np.linalg.norm(
                mesh.extents):
            part_vertices, part_faces = decimate(np.asarray(hull.vertices), np.asarray(hull.faces), budget)[:2]
            hulls += 1
        else:
            part_vertices, part_faces = remesh_and_decimate(np.asarray(mesh.vertices), np.asarray(mesh.faces), budget)
        out_vertices.append(part_vertices)
        out_faces.append(part_faces + count)
        count += len(part_vertices)
    out_faces = np.concatenate(out_faces)
    share = total / seen_area.sum()
    summary = (f"kept the {len(kept)} of {len(seen_area)} parts with the most visible area ({share:.0%} of it): "
               f"{hulls} as convex hulls, {len(kept) - hulls} remeshed; {len(faces):,} -> {len(out_faces):,} triangles")
    return np.concatenate(out_vertices), out_faces, summary
