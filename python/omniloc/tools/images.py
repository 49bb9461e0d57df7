"""Pictures embedded in report.html, compressed so that the page stays small (PIL only, no matplotlib).
"""
from __future__ import annotations

import io
from typing import Any


def compress_png(path: Any) -> Any:
    """Re-encodes a picture so that report.html, which embeds every one, stays under 3 MB without
    leaving one out: plots (few colours) as an optimised 256-colour palette PNG; camera frames and
    other photographic pictures, which stay large as a palette PNG, as JPEG (quality 85). Keeps the
    original where that is smaller. Returns the path written (the suffix may change to .jpg).
    Without PIL (Debian's python3-pil, a dependency of python3-matplotlib) nothing changes."""
    try:
        from PIL import Image
    except ImportError:
        return path
    import io
    with Image.open(path) as im:
        im.load()
    has_alpha = im.mode in ("RGBA", "LA") or (im.mode == "P" and "transparency" in im.info)
    src = im.convert("RGBA") if has_alpha else im.convert("RGB")
    q = src.quantize(colors=256, method=Image.Quantize.FASTOCTREE) if has_alpha else src.quantize(colors=256)
    buf = io.BytesIO()
    q.save(buf, format="PNG", optimize=True)
    best, data = path.stat().st_size, None
    if buf.tell() < best:
        best, data = buf.tell(), buf.getvalue()
    if best > 120_000 and not has_alpha:  # still large: a photograph-like picture
        jbuf = io.BytesIO()
        src.save(jbuf, format="JPEG", quality=85, optimize=True)
        if jbuf.tell() < best / 2:
            path.unlink()
            path = path.with_suffix(".jpg")
            path.write_bytes(jbuf.getvalue())
            return path
    if data is not None:
        path.write_bytes(data)
    return path
