"""Export: pick clips and a dataset format, download one archive."""

import shutil
import tempfile
from pathlib import Path

import streamlit as st

from partlab.app import state
from partlab.app.runs import safe_name
from partlab.app.views.common import require_project
from partlab.labelling import formats

s = state.store()
st.title("Export")
project = require_project(s)

clips = {c.id: c for c in s.clips(project.id)}
with st.form("export"):
    picked = st.multiselect("Clips", list(clips), default=list(clips), format_func=lambda i: clips[i].name)
    c1, c2, c3 = st.columns(3)
    fmt = c1.selectbox("Format", list(formats.FORMATS), format_func=lambda f: f"{f}: {formats.FORMATS[f].description}")
    every = c2.number_input("Every n-th frame", min_value=1, value=1, step=1)
    with_frames = c3.checkbox("Include frame images", value=False)
    go = st.form_submit_button("Build archive", type="primary")

if go:
    if not picked:
        st.error("Pick at least one clip.")
        st.stop()
    work = Path(tempfile.mkdtemp(prefix="partlab-export-"))
    try:
        with st.spinner("Exporting..."):
            for cid in picked:  # export_clip marks each clip exported
                formats.export_clip(s, cid, fmt, work / "dataset" / f"{cid}_{safe_name(Path(clips[cid].name).stem)}",
                                    every=int(every), frames=with_frames)
            archive = shutil.make_archive(str(work / f"{safe_name(project.name)}-{fmt}"), "zip", work / "dataset")
            data = Path(archive).read_bytes()
        st.session_state["export_archive"] = (Path(archive).name, data)
        st.success(f"Exported {len(picked)} clip(s) as {fmt}: {len(data) / 1024:.0f} kB.")
    except (ValueError, OSError) as exc:
        st.error(f"Export failed: {exc}")
    finally:
        shutil.rmtree(work, ignore_errors=True)

if "export_archive" in st.session_state:
    name, data = st.session_state["export_archive"]
    st.download_button(f"Download {name}", data, file_name=name, mime="application/zip")
