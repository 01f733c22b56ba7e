"""The box editor: a bidirectional Streamlit component (components v2) in plain HTML/JS/CSS.

The browser side (``editor.js``) keeps a cache of JPEG frames and their boxes, which it
asks for in chunks around the shown frame and ahead while playing (the state value
``view``), so stepping and playing do not wait for a rerun. It draws the frame with every
box in its track's colour, zooms and pans, shows labels on hover or for all boxes, hides
parts and tracks, draws a timeline per track, lets the user move, resize, add and delete
boxes and toggle the failure/occluded flags, and sends each action as an event. This wrapper returns only the
events Python has not seen yet (their ``seq`` is above the last applied one, kept in
session state), so a rerun never applies an edit twice and an action made while
Python was busy is re-sent until acknowledged.

Events (dicts): ``{"kind": "edit", "frame", "track_id", "part", "box": [x, y, w, h],
"failure", "occluded", "revision", "added"?}``, ``{"kind": "delete", "frame",
"track_id", "part", "revision"}``, ``{"kind": "frame", "target"}``, ``{"kind": "undo"}``,
``{"kind": "redo"}``, ``{"kind": "occluders", "boxes": [[x, y, w, h], ...]}``, and for the
timeline's events ``{"kind": "event_add", "type", "start_frame", "end_frame"}``,
``{"kind": "event_edit", "event_id", "revision", "start_frame"?, "end_frame"?, "type"?}``,
``{"kind": "event_delete", "event_id", "revision"}``. Box edits and deletes also carry
``based_on``: the ``seq`` of this editor's earlier edit whose optimistic revision they expect
(0: the revision came from Python), so an edit made on top of a refused one is refused too.
"""

from __future__ import annotations

import base64
from collections.abc import Callable
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


def pack_boxes(boxes: pd.DataFrame, parts: tuple[str, ...] = PART_NAMES) -> dict[int, list[list]]:
    """Rows of a tracks frame as the editor's compact boxes by frame: ``[track_id, part
    index, x, y, w, h, flags, occluded, revision]`` with flags 1 = failure, 2 = human (a keyframe)."""
    if not len(boxes):
        return {}
    index = {p: i for i, p in enumerate(parts)}
    flags = boxes["failure"].astype(bool).to_numpy().astype(int) + 2 * (boxes["source"] == "human").to_numpy()
    rev = boxes["revision"].to_numpy() if "revision" in boxes else np.zeros(len(boxes), int)
    cols = zip(boxes["frame"].to_numpy().tolist(), boxes["track_id"].to_numpy().tolist(),
               boxes["part"].map(index).fillna(-1).astype(int).tolist(),
               *(boxes[c].to_numpy(float).tolist() for c in ("x", "y", "w", "h")),  # exact: a move keeps the size
               flags.tolist(), np.round(boxes["occluded"].to_numpy(float), 3).tolist(), rev.tolist())
    out: dict[int, list[list]] = {}
    for f, t, p, x, y, w, h, fl, o, r in cols:
        out.setdefault(int(f), []).append([int(t), p, x, y, w, h, int(fl), o, int(r)])
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


def _value(key: str) -> dict:
    try:
        value = st.session_state[key]
    except (KeyError, AttributeError):
        return {}
    return value if isinstance(value, dict) or hasattr(value, "get") else {}


def pending_events(key: str) -> list[dict]:
    """The editor's new events, read *before* it is drawn in this run.

    A component's trigger values are visible in ``st.session_state[key]`` from the
    start of the run it caused, so the page can apply them and draw the editor with
    the result at once, instead of drawing stale boxes and rerunning.
    """
    return _new_events(_value(key).get("events"), key)


def view(key: str) -> dict:
    """What the editor shows and asks for: ``{frame, lo, hi, blo, bhi, req}`` (frames
    ``lo..hi-1`` and the boxes of ``blo..bhi-1`` to send), ``{}`` before its first report."""
    v = _value(key).get("view")
    return dict(v) if isinstance(v, dict) or hasattr(v, "get") else {}


MAX_CHUNK = 48  # frames sent in one run at most (about 3 MB of JPEG at 768x576)


def box_editor(*, key: str, width: int, height: int, frame_count: int, fps: float,
               frame_url: Callable[[int], str], boxes_by_frame: dict[int, list[list]], version, jump: dict,
               tracks: list[dict], next_track_id: int = 1, parts: tuple[str, ...] = PART_NAMES,
               used_parts: list[str] | None = None, timeline: dict | None = None, mode: str = "boxes",
               occluders: list[dict] | None = None, component_width: int | str = "stretch") -> list[dict]:
    """Show the editor and return the new events not yet taken by :func:`pending_events`.

    ``frame_url(i)``: frame ``i`` as a JPEG data URL; ``boxes_by_frame``: :func:`pack_boxes`
    of the clip's effective boxes (of ``version``); ``jump``: ``{seq, frame}``, a new ``seq``
    makes the editor show ``frame``; ``tracks``: ``[{id, colour, state}]``; ``timeline``:
    ``{tracks: [{id, colour, spans, keys, fails, acc, rej}], flagged, events: [{id, revision, start, end,
    type, colour}], kinds}``.
    """
    if mode not in ("boxes", "occluders"):
        raise ValueError(f"mode must be 'boxes' or 'occluders', got {mode!r}")
    v = view(key)
    req, version = int(v.get("req", 0)), str(version)
    served_key = f"{key}:served"
    sent = st.session_state.get(served_key)
    st.session_state[served_key] = (req, version)
    lo, hi = int(v.get("lo", 0)), int(v.get("hi", 0))
    blo, bhi = int(v.get("blo", 0)), int(v.get("bhi", 0))
    if not v:  # before the editor's first request: the frame to show, a few after it and their boxes
        lo = int(jump.get("frame", 0))
        hi, blo, bhi = lo + 8, lo - 10, lo + 120
    elif sent is not None and sent[0] == req:  # answered by an earlier run: no frames again
        lo = hi = 0
        if sent[1] == version:
            blo = bhi = 0
    if v and (sent is None or sent[1] != version):  # boxes changed: those around the shown frame again
        f = int(v.get("frame", jump.get("frame", 0)))
        blo, bhi = (min(blo, f - 10), max(bhi, f + 60)) if bhi > blo else (f - 10, f + 60)
    lo, hi = max(0, lo), min(frame_count, hi, max(lo, 0) + MAX_CHUNK)
    blo, bhi = max(0, blo), min(frame_count, bhi)
    chunk = dict(req=req, lo=lo, frames=[frame_url(i) for i in range(lo, hi)], blo=blo, bhi=bhi,
                 version=str(version),
                 boxes={str(f): boxes_by_frame.get(f, []) for f in range(blo, bhi) if f in boxes_by_frame})
    done = int(st.session_state.get(applied_key(key), 0))
    data = dict(width=int(width), height=int(height), frame_count=int(frame_count), fps=float(fps),
                parts=list(parts), used_parts=list(used_parts or parts), tracks=tracks,
                colours={str(t["id"]): t["colour"] for t in tracks}, next_track_id=int(next_track_id), mode=mode,
                applied_seq=done, version=str(version), jump=dict(jump), chunk=chunk, timeline=timeline or {},
                occluders=occluders or [])
    result = _component()(key=key, data=data, width=component_width, on_events_change=lambda: None,
                          on_view_change=lambda: None)
    return _new_events(result.get("events"), key)
