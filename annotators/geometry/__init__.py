"""Geometry shared by experts: oriented boxes, the upright support frame, grid segmentation primitives."""
