"""Launch ``streamlit run`` for partlab (what ``partlab app`` executes).

The page scripts live in ``app/pages/`` and are declared with ``st.navigation``;
Streamlit would otherwise take that folder for a legacy (v1) pages directory and,
on a fresh server opened at a deep link such as ``/correct``, run the page without
the entry script (no project picker, its helper modules listed as pages). Setting
the flag that ``st.navigation`` itself sets on its first call avoids that.
"""

from __future__ import annotations

import sys


def main(argv: list[str]) -> int:
    from streamlit.runtime.pages_manager import PagesManager
    from streamlit.web import cli

    PagesManager.uses_pages_directory = False
    sys.argv = ["streamlit", "run", *argv]
    return cli.main()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
