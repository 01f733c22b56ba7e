"""Entry page of the Streamlit app (placeholder until the app issue lands)."""

import streamlit as st

from labelling.config import data_dir

st.set_page_config(page_title="partlab", layout="wide")
st.title("partlab")
st.write("Label human body parts in video: track, correct, learn, export.")
st.caption(f"Data directory: {data_dir()}")
