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
    others ``track_id + offset`` (rows :func:`relabel_on_people` gave a body id keep it); a limb head
    is dropped where the body tracker has that person's
    head in the same frame (one head box per person and frame)."""
    limbs = limbs.copy()
    moved = limbs.pop("relabelled").to_numpy(bool) if "relabelled" in limbs else np.zeros(len(limbs), bool)
    ids = limbs["track_id"].to_numpy(np.int64).copy()
    ids[~moved] = remap_ids(ids[~moved], mapping, offset)  # relabelled rows carry their body id already
    limbs["track_id"] = ids
    body_heads = body.loc[body["part"] == "head", ["frame", "track_id"]]
    key = pd.MultiIndex.from_frame(body_heads)
    dup = (limbs["part"] == "head") & pd.MultiIndex.from_frame(limbs[["frame", "track_id"]]).isin(key)
    return pd.concat([body, limbs[~dup]], ignore_index=True)


def relabel_on_people(body: pd.DataFrame, limbs: pd.DataFrame, mapping: dict[int, int],
                      head_top: float) -> tuple[pd.DataFrame, dict[int, int]]:
    """Rows of limb people no body person was matched to (:func:`match_limb_people`), relabelled
    frame by frame to the body person they are on: a head whose centre lies in the top ``head_top``
    of one body ``person`` box of its frame, a hand inside one (the nearest box centre when several
    hold it); rows on nobody are dropped. Where this gives a body person two rows of one part in a
    frame, its own matched limb row (else the higher score) stays. Returns the limb rows (matched
    ones keep their limb ids, relabelled ones carry the body id in ``track_id`` and ``relabelled``
    True) and, per unmatched limb id, the body id it was given most often (for its events)."""
    limbs = limbs.assign(relabelled=False)
    free = ~limbs["track_id"].isin(list(mapping))
    people = body[body["part"] == "person"][["frame", "track_id", "x", "y", "w", "h"]]
    if not free.any() or people.empty:
        return limbs[~free], {}
    rows = limbs[free].reset_index(drop=True)
    m = rows[["frame", "part", "x", "y", "w", "h"]].reset_index().merge(people, on="frame", suffixes=("", "_p"))
    cx, cy = m["x"] + m["w"] / 2, m["y"] + m["h"] / 2
    top = np.where(m["part"] == "head", head_top, 1.0)
    m = m[(cx >= m["x_p"]) & (cx <= m["x_p"] + m["w_p"]) & (cy >= m["y_p"]) & (cy <= m["y_p"] + top * m["h_p"])].copy()
    m["d"] = np.hypot(m["x"] + m["w"] / 2 - m["x_p"] - m["w_p"] / 2, m["y"] + m["h"] / 2 - m["y_p"] - m["h_p"] / 2)
    best = m.sort_values("d", kind="stable").groupby("index").head(1).set_index("index")["track_id"]
    moved = rows.loc[best.index].assign(track_id=best.to_numpy().astype(np.int64), relabelled=True,
                                        _limb=rows.loc[best.index, "track_id"].to_numpy())
    given = moved.groupby("_limb")["track_id"].agg(lambda ids: int(ids.mode().iloc[0])).to_dict()
    own = limbs[~free].copy()
    own["_own"] = own["track_id"].map(mapping)
    both = pd.concat([own.assign(_key=own["_own"], _rank=0), moved.assign(_key=moved["track_id"], _rank=1)],
                     ignore_index=True)
    score = both["score"] if "score" in both else pd.Series(0.0, index=both.index)
    both = both.assign(_s=-score.fillna(0.0)).sort_values(["_rank", "_s"], kind="stable")
    both = both.drop_duplicates(["frame", "_key", "part"]).sort_index()
    out = both.drop(columns=["_own", "_key", "_rank", "_s", "_limb"], errors="ignore")
    return out, {int(k): v for k, v in given.items()}
