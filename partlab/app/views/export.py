"""Export: pick clips and a dataset format, download one archive."""

import shutil
import tempfile
from pathlib import Path

import streamlit as st

from partlab.app import state
from partlab.app.runs import safe_name
from partlab.app.views.common import plain, require_project, storage_message
from partlab.labelling import formats
from partlab.labelling.config import data_dir

s = state.store()
st.title("Export")
project = require_project(s)

clips = {c.id: c for c in s.clips(project.id)}
with st.form("export"):
    picked = st.multiselect("Clips", list(clips), default=list(clips), format_func=lambda i: clips[i].name)
    c1, c2, c3, c4 = st.columns(4)
    fmt = c1.selectbox("Format", list(formats.FORMATS), format_func=lambda f: f"{f}: {formats.FORMATS[f].description}")
    every = c2.number_input("Every n-th frame", min_value=1, value=1, step=1)
    with_frames = c3.checkbox("Include frame images", value=False)
    accepted_only = c4.checkbox("Accepted frames only", value=False,
                                help="only the boxes of tracks at frames accepted in the review pass (Correct page)")
    go = st.form_submit_button("Build archive", type="primary")

EXPORTS = data_dir() / "exports"


def _old_archives(keep: int = 4) -> None:
    """Archives are files in the data directory, not server memory; the oldest beyond ``keep`` go."""
    for old in sorted(EXPORTS.glob("*/*.zip"), key=lambda p: p.stat().st_mtime)[:-keep]:
        shutil.rmtree(old.parent, ignore_errors=True)


if go:
    if not picked:
        st.error("Pick at least one clip.")
        st.stop()
    EXPORTS.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix="export-", dir=EXPORTS))
    try:
        with st.spinner("Exporting..."):
            for cid in picked:  # export_clip marks each clip exported
                formats.export_clip(s, cid, fmt, work / "dataset" / f"{cid}_{safe_name(Path(clips[cid].name).stem)}",
                                    every=int(every), frames=with_frames, accepted_only=accepted_only)
            archive = Path(shutil.make_archive(str(work / f"{safe_name(project.name)}-{fmt}"), "zip",
                                               work / "dataset"))
            shutil.rmtree(work / "dataset", ignore_errors=True)
        st.session_state["export_archive"] = str(archive)
        st.success(f"Exported {len(picked)} clip(s) as {fmt}: {archive.stat().st_size / 1024:.0f} kB.")
        _old_archives()
    except (ValueError, OSError) as exc:
        shutil.rmtree(work, ignore_errors=True)
        st.error(storage_message(exc) if isinstance(exc, OSError) else plain(f"Export failed: {exc}"))

archive = Path(st.session_state.get("export_archive", ""))
if archive.name and archive.is_file():
    # deferred: the file is read from disk only when the user clicks, not kept in memory per session
    st.download_button(f"Download {plain(archive.name)}", lambda: archive.open("rb"), file_name=archive.name,
                       mime="application/zip")
