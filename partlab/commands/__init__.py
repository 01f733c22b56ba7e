"""One module per ``partlab`` sub-command: ``add_arguments(parser)`` and ``run(args)``."""
