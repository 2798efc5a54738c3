"""The ``robokudo`` subcommands, one module each (``HELP``, ``add_arguments``, ``run``)."""
