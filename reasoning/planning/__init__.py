"""Query planning: interpretation of a query against the ontology, the planner that chooses and chains
annotators, and the Plan it produces (with the reason for every step)."""
