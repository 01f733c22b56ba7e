"""The roles a user may hold in one project (store revision 5), weakest first.

A ``viewer`` reads and exports, an ``annotator`` also edits, tracks, trains and uploads, an
``owner`` also grants roles (:mod:`partlab.labelling.access` enforces them). A module of its own
so that ``partlab users --help`` does not load the store.
"""

ROLES: tuple[str, ...] = ("viewer", "annotator", "owner")
