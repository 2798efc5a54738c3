"""Pixel experts: colour naming, colour histograms, colour-only segmentation, the ONNX detector."""
