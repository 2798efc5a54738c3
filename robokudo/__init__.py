"""robokudo: a knowledge-enabled perception framework for mobile manipulation.

This package's root exports the runtime core (:mod:`robokudo.core`); the application built on all other
packages (CLI, answering service) lives in :mod:`robokudo.application`.
"""

from robokudo.core.annotator import Annotator, AnnotatorError, ConditionAnnotator, PortError
from robokudo.core.capability import Capability
from robokudo.core.cas import CAS
from robokudo.core.composites import Fallback, Sequence
from robokudo.core.dataflow import DataFlowError, data_flow_violations, validate_data_flow
from robokudo.core.engine import Engine, TaskInterface
from robokudo.core.parallel import ThresholdParallel
from robokudo.core.pipeline import Pipeline, StructureError
from robokudo.core.slot import TaskSlot
from robokudo.core.structure import check_structure
from robokudo.core.threaded import ThreadedAnnotator

__all__ = [
    "CAS",
    "Annotator",
    "AnnotatorError",
    "Capability",
    "ConditionAnnotator",
    "DataFlowError",
    "Engine",
    "Fallback",
    "Pipeline",
    "PortError",
    "Sequence",
    "StructureError",
    "TaskInterface",
    "TaskSlot",
    "ThreadedAnnotator",
    "ThresholdParallel",
    "check_structure",
    "data_flow_violations",
    "validate_data_flow",
]
