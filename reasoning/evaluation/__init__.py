"""Scoring perception against labelled data: segmentation scores (``reasoning.evaluation.segmentation``) and the
labelling conventions of the datasets scored (``reasoning.evaluation.mosd``)."""
