"""robokudo: a knowledge-enabled perception framework for mobile manipulation (the runtime package)."""

from robokudo.annotator import Annotator, AnnotatorError, ConditionAnnotator, PortError
from robokudo.cas import CAS
from robokudo.dataflow import DataFlowError, data_flow_violations, validate_data_flow
from robokudo.engine import Engine, TaskInterface
from robokudo.parallel import ThresholdParallel
from robokudo.pipeline import Pipeline, StructureError
from robokudo.slot import TaskSlot
from robokudo.structure import check_structure
from robokudo.threaded import ThreadedAnnotator

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
