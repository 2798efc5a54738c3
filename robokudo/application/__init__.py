"""The application on top of every other package: the answering service, the CLI and its commands."""
