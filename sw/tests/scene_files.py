"""A shipped scene file copied for a test: another screen size, and the paths of its OBJ
files and background picture made absolute so the copy works from a temporary folder
(test_pipeline.py, test_meshes.py)."""
from __future__ import annotations

from pathlib import Path


def scene_copy(src: Path, dst: Path, screen: tuple[int, int] | None = None,
               background: str | None = None) -> Path:
    """Write `src` to `dst` with `screen W H` replaced by `screen` (if given) and a flat
    `background R G B` replaced by `background` (if given); returns dst."""
    out = []
    for line in src.read_text().splitlines():
        tok = line.split()
        if tok[:1] == ["screen"] and screen:
            line = f"screen {screen[0]} {screen[1]}"
        elif tok[:1] == ["obj"]:
            tok[1] = str((src.parent / tok[1]).resolve())
            line = " ".join(tok)
        elif tok[:2] == ["background", "image"]:
            line = f"background image {(src.parent / tok[2]).resolve()}"
        elif tok[:1] == ["background"] and background:
            line = f"background {background}"
        out.append(line)
    dst.write_text("\n".join(out) + "\n")
    return dst
