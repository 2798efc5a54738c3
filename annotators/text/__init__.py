"""Text reading (OCR) on object hypotheses."""
