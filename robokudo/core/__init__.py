"""The runtime core: CAS and types, annotators with declared ports and capabilities, PPT node classes, the
engine with its task interface, the data-flow validator and rendering. It imports no package above it."""
