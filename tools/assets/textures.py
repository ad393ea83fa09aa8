"""Generate the scene's procedural textures into `lerobot_tavis/assets/scene/` (no third-party source).

    .venv/bin/python tools/assets/textures.py

Every texture tiles seamlessly (all filtering is periodic, done in the Fourier domain) and is drawn from its own
fixed-seed generator, so a rerun writes the same pixels. Colours are near-white where a material tints them
(`lerobot_tavis/envs/scene.py` sets the tints); the floor tile carries its final colours.

- `brushed_metal.png`: table top, 512 px for one period (scene.py maps one period to 1 m): fine streaks along
  the image's horizontal axis plus faint smudges.
- `floor_tile.png`: one dark floor tile with light grout at its border, 256 px for one tile (0.5 m).
- `wood.png`: warm wood grain along the image's vertical axis (a box face's second axis: y on the shelf's
  boards), 512 px for one period (0.5 m): the shelf.
- `cardboard.png`: light, smooth board without grain, 256 px for one period (0.25 m): the peeking box.
"""

from __future__ import annotations

import numpy as np
from common import Provenance, staged_group, write_notice, write_texture  # tools/assets/ is the script's path

MAX_BYTES = 3_000_000  # the whole group


def periodic_blur(noise: np.ndarray, sigma_rows: float, sigma_cols: float) -> np.ndarray:
    """Gaussian blur (standard deviations in pixels along rows and columns) with wrap-around borders."""
    fy = np.fft.fftfreq(noise.shape[0])[:, None]
    fx = np.fft.fftfreq(noise.shape[1])[None, :]
    kernel = np.exp(-2.0 * np.pi**2 * ((sigma_rows * fy) ** 2 + (sigma_cols * fx) ** 2))
    return np.real(np.fft.ifft2(np.fft.fft2(noise) * kernel))


def smooth_noise(rng: np.random.Generator, shape: tuple[int, int], sigma_rows: float, sigma_cols: float) -> np.ndarray:
    """Tileable Gaussian noise with zero mean and unit standard deviation."""
    field = periodic_blur(rng.standard_normal(shape), sigma_rows, sigma_cols)
    return (field - field.mean()) / field.std()


def to_rgb8(rgb: np.ndarray) -> np.ndarray:
    return np.round(np.clip(rgb, 0.0, 1.0) * 255.0).astype(np.uint8)


def brushed_metal(size: int = 512) -> np.ndarray:
    """Light grey with long horizontal brush streaks and broad smudges; mean about 0.9."""
    rng = np.random.default_rng(1701)
    shape = (size, size)
    value = (0.90
             + 0.012 * smooth_noise(rng, shape, 0.6, 24.0)  # fine streaks
             + 0.008 * smooth_noise(rng, shape, 3.0, 80.0)  # broader brush passes
             + 0.015 * smooth_noise(rng, shape, 40.0, 40.0))  # smudges
    return to_rgb8(np.repeat(value[..., None], 3, axis=2))


def floor_tile(size: int = 256, grout_px: float = 3.0) -> np.ndarray:
    """A dark grey tile with a light grout line (`grout_px` wide on each border, so twice that between tiles)."""
    rng = np.random.default_rng(2718)
    shape = (size, size)
    tile = 0.12 + 0.010 * smooth_noise(rng, shape, 1.5, 1.5) + 0.015 * smooth_noise(rng, shape, 30.0, 30.0)
    centre = np.arange(size) + 0.5
    to_edge = np.minimum(centre, size - centre)  # distance (px) from a pixel centre to the nearer border
    distance = np.minimum(to_edge[:, None], to_edge[None, :])
    grout = np.clip(grout_px + 0.5 - distance, 0.0, 1.0)  # 1 inside the line, a one-pixel soft edge
    value = tile * (1.0 - grout) + 0.55 * grout
    return to_rgb8(np.repeat(value[..., None], 3, axis=2))


def wood(size: int = 512, rings: int = 24) -> np.ndarray:
    """Wood grain along the vertical axis: `rings` growth lines per period, warped, with fine fibres."""
    rng = np.random.default_rng(31415)
    shape = (size, size)
    cols = np.arange(size)[None, :] / size
    warp = 0.9 * smooth_noise(rng, shape, 90.0, 25.0) + 0.25 * smooth_noise(rng, shape, 30.0, 6.0)
    late = (0.5 + 0.5 * np.sin(2.0 * np.pi * rings * cols + warp)) ** 3  # thin darker latewood lines
    fibres = smooth_noise(rng, shape, 20.0, 0.7)
    value = 0.96 - 0.07 * late + 0.02 * fibres + 0.02 * smooth_noise(rng, shape, 50.0, 50.0)
    return to_rgb8(warm(value))


def cardboard(size: int = 256) -> np.ndarray:
    """Smooth light board: fine speckle, faint fibres and broad blotches, no grain lines."""
    rng = np.random.default_rng(16180)
    shape = (size, size)
    value = (0.95 + 0.015 * smooth_noise(rng, shape, 0.8, 0.8) + 0.012 * smooth_noise(rng, shape, 0.6, 8.0)
             + 0.02 * smooth_noise(rng, shape, 25.0, 25.0))
    return to_rgb8(warm(value))


def warm(value: np.ndarray) -> np.ndarray:
    """Grey levels to RGB where darker is also a little more saturated (redder), as in wood and paper."""
    return np.stack([value, value**1.15, value**1.45], axis=2)


TEXTURES = {
    "brushed_metal.png": (brushed_metal, "brushed metal (table top), seed 1701"),
    "floor_tile.png": (floor_tile, "dark floor tile with light grout, seed 2718"),
    "wood.png": (wood, "light wood grain (shelf), seed 31415"),
    "cardboard.png": (cardboard, "light board (peeking box), seed 16180"),
}


def main() -> None:
    with staged_group("scene", MAX_BYTES) as staging:
        entries = []
        for name, (make, what) in TEXTURES.items():
            write_texture(staging / name, make())
            entries.append(Provenance(file=name, repository="this project (tools/assets/textures.py)", commit="n/a",
                                      source_path="", license="MIT (this project)", changes=f"procedural: {what}"))
        write_notice(staging, "Scene textures",
                     "Generated by this project with `tools/assets/textures.py` (procedural noise from fixed seeds); "
                     "no third-party source, image or code was used.", entries)

if __name__ == "__main__":
    main()
