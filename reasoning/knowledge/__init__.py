"""The knowledge base: the ontology (Turtle files plus the annotator classes' declarations) loaded once and
indexed for typed questions; validated editing; HermiT classification."""
