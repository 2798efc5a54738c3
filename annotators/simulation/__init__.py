"""The built-in kitchen: a deterministic RGB-D renderer with ground truth, its regions read from the map."""
