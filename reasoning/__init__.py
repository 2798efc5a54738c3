"""Reasoning over knowledge: the ontology's knowledge base (``reasoning.knowledge``), query planning
(``reasoning.planning``), fusion of expert statements (``reasoning.fusion``) and the belief store with the
answers drawn from it (``reasoning.beliefs``)."""
