"""The box editor: a bidirectional Streamlit component (components v2) in plain HTML/JS/CSS.

The browser side (``editor.js``) draws the frame with every box in its track's colour,
lets the user move, resize, add and delete boxes and toggle the failure/occluded flags
(keyboard: arrows or A/D frame, N/Tab next track, F failure, O occluded, Delete,
Ctrl+Z/Ctrl+Y), and sends each action as an event. This wrapper returns only the
events Python has not seen yet (their ``seq`` is above the last applied one, kept in
session state), so a rerun never applies an edit twice and an action made while
Python was busy is re-sent until acknowledged.

Events (dicts): ``{"kind": "edit", "frame", "track_id", "part", "box": [x, y, w, h],
"failure", "occluded", "revision", "added"?}``, ``{"kind": "delete", "frame",
"track_id", "part", "revision"}``, ``{"kind": "frame", "target"}``, ``{"kind": "undo"}``,
``{"kind": "redo"}``, ``{"kind": "occluders", "boxes": [[x, y, w, h], ...]}``.
"""

from __future__ import annotations

import base64
from functools import lru_cache
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import streamlit as st

from partlab.tracking.parts import PART_NAMES

HERE = Path(__file__).resolve().parent
COMPONENT_NAME = "partlab_box_editor"

#: 10 well separated colours (Tableau 10); track ``i`` gets ``PALETTE[i % 10]``.
PALETTE: tuple[str, ...] = ("#4e79a7", "#f28e2b", "#e15759", "#76b7b2", "#59a14f",
                            "#edc948", "#b07aa1", "#ff9da7", "#9c755f", "#bab0ac")


def track_colour(track_id: int) -> str:
    """The colour of a track, the same in the editor and in the plots."""
    return PALETTE[int(track_id) % len(PALETTE)]


@lru_cache(maxsize=1)
def _component():
    return st.components.v2.component(
        COMPONENT_NAME,
        html=(HERE / "editor.html").read_text(encoding="utf-8"),
        css=(HERE / "editor.css").read_text(encoding="utf-8"),
        js=(HERE / "editor.js").read_text(encoding="utf-8"),
    )


def encode_image(image: np.ndarray, quality: int = 85) -> str:
    """A BGR ``(H, W, 3) uint8`` frame as a JPEG data URL (what the browser shows)."""
    ok, buf = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, quality])
    if not ok:
        raise ValueError("could not encode the frame as JPEG")
    return "data:image/jpeg;base64," + base64.b64encode(buf.tobytes()).decode("ascii")


def boxes_payload(boxes: pd.DataFrame) -> list[dict]:
    """Rows of a tracks frame (one video frame) as the editor's box dicts."""
    out = []
    for r in boxes.itertuples(index=False):
        out.append(dict(track_id=int(r.track_id), part=str(r.part), x=float(r.x), y=float(r.y), w=float(r.w),
                        h=float(r.h), failure=bool(r.failure), occluded=float(r.occluded),
                        revision=int(getattr(r, "revision", 0)), source=str(getattr(r, "source", "")),
                        colour=track_colour(int(r.track_id))))
    return out


def applied_key(key: str) -> str:
    return f"{key}:applied_seq"


def _new_events(raw, key: str) -> list[dict]:
    """Events above the last applied ``seq``, oldest first; marks them applied."""
    done = int(st.session_state.get(applied_key(key), 0))
    events = [e for e in (raw or []) if isinstance(e, dict) and int(e.get("seq", 0)) > done]
    events.sort(key=lambda e: int(e["seq"]))
    if events:
        st.session_state[applied_key(key)] = int(events[-1]["seq"])
    return events


def pending_events(key: str) -> list[dict]:
    """The editor's new events, read *before* it is drawn in this run.

    A component's trigger values are visible in ``st.session_state[key]`` from the
    start of the run it caused, so the page can apply them and draw the editor with
    the result at once, instead of drawing stale boxes and rerunning.
    """
    try:
        value = st.session_state[key]
    except (KeyError, AttributeError):
        return []
    raw = value.get("events") if isinstance(value, dict) else None
    return _new_events(raw, key)


def box_editor(image: np.ndarray, boxes: pd.DataFrame | list[dict], *, key: str, frame: int, frame_count: int,
               tracks: list[int] | None = None, next_track_id: int = 1, parts: tuple[str, ...] = PART_NAMES,
               mode: str = "boxes", width: int | str = "stretch") -> list[dict]:
    """Show the editor and return the new events not yet taken by :func:`pending_events`.

    ``boxes``: the frame's effective boxes (tracks CSV columns + ``revision``), or dicts
    ``{x, y, w, h}`` for ``mode="occluders"``.
    """
    if mode not in ("boxes", "occluders"):
        raise ValueError(f"mode must be 'boxes' or 'occluders', got {mode!r}")
    if isinstance(boxes, pd.DataFrame):
        payload = boxes_payload(boxes)
    else:
        payload = [dict(track_id=i, part="occluder", failure=False, occluded=0, revision=0, colour="#000",
                        **{k: float(b[k]) for k in ("x", "y", "w", "h")}) for i, b in enumerate(boxes)]
    done = int(st.session_state.get(applied_key(key), 0))
    data = dict(image=encode_image(image), width=int(image.shape[1]), height=int(image.shape[0]), frame=int(frame),
                frame_count=int(frame_count), boxes=payload, parts=list(parts),
                tracks=sorted(int(t) for t in (tracks or [])), next_track_id=int(next_track_id), mode=mode,
                applied_seq=done)
    result = _component()(key=key, data=data, width=width, on_events_change=lambda: None)
    return _new_events(result.get("events"), key)
