"""The one exception type a user sees as a sentence.

Anything that fails because of what a user gave (a file, an option, an edit) raises
:class:`UserError` (or a subclass) with a message that names what and where; the command
line prints ``partlab CMD: message`` and exits 2, the app shows the message. Computation
packages raise it without importing the command line.
"""


class UserError(ValueError):
    """A user-facing failure: the message names the input and what is wrong with it."""
