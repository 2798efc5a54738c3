"""Reasoning over the ontology: the knowledge base (``reasoning.knowledge_base``), validated editing
(``reasoning.editing``), code/ontology agreement (``reasoning.capabilities``) and the ``robokudo ontology``
subcommand (``reasoning.ontology_cli``)."""
