"""One identity per person when the body and limb trackers both run (``--tracker all``).

Started from ``--init`` both trackers use the given track ids. Started automatically they find
people independently (foreground blobs against skin blobs and faces) and number them on their
own, so the same person would appear as two tracks. :func:`match_limb_people` pairs each limb
person with the body person whose box holds its head in most of the frames both are tracked.
"""

from __future__ import annotations

import numpy as np
import pandas as pd


def match_limb_people(body: pd.DataFrame, limbs: pd.DataFrame, min_frames: int = 10,
                      min_share: float = 0.6) -> dict[int, int]:
    """``{limb track_id: body track_id}`` for limb people whose head centre lies inside one body
    person's ``person`` box in at least ``min_share`` of their common frames (and at least
    ``min_frames`` frames). One-to-one: the pairs with most such frames are taken first."""
    persons = body[body["part"] == "person"][["frame", "track_id", "x", "y", "w", "h"]]
    heads = limbs[limbs["part"] == "head"][["frame", "track_id", "x", "y", "w", "h"]]
    if persons.empty or heads.empty:
        return {}
    m = heads.merge(persons, on="frame", suffixes=("_l", "_b"))
    cx = m["x_l"] + m["w_l"] / 2.0
    cy = m["y_l"] + m["h_l"] / 2.0
    inside = (cx >= m["x_b"]) & (cx <= m["x_b"] + m["w_b"]) & (cy >= m["y_b"]) & (cy <= m["y_b"] + m["h_b"])
    common = m.groupby(["track_id_l", "track_id_b"]).size()
    hits = m[inside].groupby(["track_id_l", "track_id_b"]).size().reindex(common.index, fill_value=0)
    share = hits / common
    ok = (hits >= min_frames) & (share >= min_share)
    pairs = sorted(((int(hits[k]), float(share[k]), int(k[0]), int(k[1])) for k in hits[ok].index), reverse=True)
    out: dict[int, int] = {}
    taken: set[int] = set()
    for _, _, limb_id, body_id in pairs:
        if limb_id in out or body_id in taken:
            continue
        out[limb_id] = body_id
        taken.add(body_id)
    return out


def remap_ids(ids, mapping: dict[int, int], offset: int) -> np.ndarray:
    """Limb track ids as written: the matched body person's id, else ``id + offset``."""
    return np.array([mapping.get(int(t), int(t) + offset) for t in ids], dtype=np.int64)


def merge_tracks(body: pd.DataFrame, limbs: pd.DataFrame, mapping: dict[int, int], offset: int) -> pd.DataFrame:
    """Body and limb rows in one table: matched limb people take their body person's id, the
    others ``track_id + offset``; a limb head is dropped where the body tracker has that person's
    head in the same frame (one head box per person and frame)."""
    limbs = limbs.copy()
    limbs["track_id"] = remap_ids(limbs["track_id"], mapping, offset)
    body_heads = body.loc[body["part"] == "head", ["frame", "track_id"]]
    key = pd.MultiIndex.from_frame(body_heads)
    dup = (limbs["part"] == "head") & pd.MultiIndex.from_frame(limbs[["frame", "track_id"]]).isin(key)
    return pd.concat([body, limbs[~dup]], ignore_index=True)
