"""Object classification from what the other experts said and the ontology's class profiles."""
