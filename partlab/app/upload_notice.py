"""An uploader's refusal as a sentence on the page, not a red icon.

Streamlit's uploader refuses a file over ``server.maxUploadSize`` in the browser, before anything
reaches the server, and says why only to screen readers (a visually hidden ``role="alert"`` text,
"File must be 1.0MB or smaller."); sighted users see a red icon. This invisible component (trusted
code, no user text in it) watches the page's uploaders and shows those texts in place, in the
uploader's own box, under the refused file's name.
"""

from __future__ import annotations

from functools import lru_cache

import streamlit as st

_JS = """
const SHOWN = "partlab-refusal";
function reveal(root) {
  for (const alert of root.querySelectorAll('[data-testid="stFileUploader"] [role="alert"]')) {
    if (alert.classList.contains(SHOWN)) continue;
    alert.classList.add(SHOWN);
    alert.style.cssText = "position:static;width:auto;height:auto;margin:0.25rem 0 0 0;clip:auto;" +
      "clip-path:none;overflow:visible;white-space:normal;display:block;color:#b3261e;font-size:0.875rem;";
    const chip = alert.parentElement;
    if (chip) { chip.style.flexWrap = "wrap"; chip.style.maxWidth = "none"; chip.style.height = "auto"; }
  }
}
export default function () {
  if (window.__partlabUploadNotice) return;
  window.__partlabUploadNotice = new MutationObserver(() => reveal(document));
  window.__partlabUploadNotice.observe(document.body, { childList: true, subtree: true });
  reveal(document);
}
"""


@lru_cache(maxsize=1)
def _component():
    return st.components.v2.component("partlab_upload_notice", html="<span></span>", js=_JS)


def show_refusals() -> None:
    """Mount the watcher once per page that has an uploader."""
    _component()(key="upload_notice")
