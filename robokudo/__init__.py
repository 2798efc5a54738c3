"""robokudo: a knowledge-enabled perception framework for mobile manipulation (the runtime package)."""

from robokudo.core.annotator import Annotator, AnnotatorError, ConditionAnnotator, PortError
from robokudo.core.cas import CAS
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
    "ConditionAnnotator",
    "DataFlowError",
    "Engine",
    "Pipeline",
    "PortError",
    "StructureError",
    "TaskInterface",
    "TaskSlot",
    "ThreadedAnnotator",
    "ThresholdParallel",
    "check_structure",
    "data_flow_violations",
    "validate_data_flow",
]
