"""Readers: every supported file layout read into the CAS, and the choice of reader for an input path."""
