"""The CAS type system: observation views and annotation dataclasses.

Every type a CAS can hold derives from :class:`CasType` and is tied to the ontology by its class name
(``rk:<ClassName>``). Two families exist:

* :class:`View` - one per CAS (the colour image, the point cloud, ...); writing a view replaces it.
* :class:`Annotation` - any number per CAS or per object hypothesis (planes, hypotheses, colours, ...).

Arrays are held by reference; nothing here copies frame data.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar, TypeVar

import numpy as np

from ontology import NAMESPACE as ONTOLOGY_NAMESPACE
from robokudo.core.geometry import pose_matrix

A = TypeVar("A", bound="Annotation")
T = TypeVar("T", bound="CasType")


class CasType:
    """Base of everything a CAS holds; the class name is the ontology term."""

    ontology_namespace: ClassVar[str] = ONTOLOGY_NAMESPACE

    @classmethod
    def iri(cls) -> str:
        """The ontology IRI of this type."""
        return cls.ontology_namespace + cls.__name__

    @classmethod
    def type_name(cls) -> str:
        """The short name used in the ontology and in messages."""
        return cls.__name__


# --------------------------------------------------------------------------------------------- views


class View(CasType):
    """An observation slot: at most one per CAS."""


@dataclass(frozen=True)
class CameraIntrinsics:
    """Pinhole intrinsics in pixels."""

    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int

    def is_valid(self) -> bool:
        """True when focal lengths are positive and the image size is non-empty."""
        return self.fx > 0 and self.fy > 0 and self.width > 0 and self.height > 0

    def matrix(self) -> np.ndarray:
        """The 3x3 camera matrix K."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def project(self, points: np.ndarray) -> np.ndarray:
        """Pixel coordinates (u, v), Nx2, of Nx3 camera-frame points in front of the camera (z > 0)."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        return np.column_stack((self.fx * p[:, 0] / p[:, 2] + self.cx, self.fy * p[:, 1] / p[:, 2] + self.cy))

    def ray(self, u: float, v: float) -> np.ndarray:
        """The camera-frame direction (z = 1) through pixel (u, v)."""
        return np.array([(u - self.cx) / self.fx, (v - self.cy) / self.fy, 1.0])


@dataclass(eq=False)
class ColorImage(View):
    """An RGB image, HxWx3 uint8."""

    image: np.ndarray


@dataclass(eq=False)
class DepthImage(View):
    """A depth image in metres along the optical axis, HxW float32; 0 or NaN means no data."""

    depth: np.ndarray


@dataclass(eq=False)
class CameraInfo(View):
    """Intrinsics, the camera pose in the world (None when unknown), the frame id, the timestamp and the recording.

    ``recording`` names the world the frame shows: the frames of one continuous recording (a sequence, the
    simulated kitchen) share it, an unrelated snapshot has its own ("" when the reader cannot tell). Without a
    camera pose, positions of frames of different recordings are never compared.
    """

    intrinsics: CameraIntrinsics
    cam_to_world: np.ndarray | None = None
    frame_id: str = "camera"
    timestamp: float = 0.0
    recording: str = ""


@dataclass(eq=False)
class PointCloud(View):
    """An organized point cloud in the camera frame.

    ``points`` is HxWx3 float32 (NaN where invalid) so every point keeps its pixel; ``mask`` (HxW bool) marks
    the points still of interest after filtering; ``colors`` is HxWx3 uint8 RGB or None.
    Filters narrow ``mask`` and share ``points``; they never copy them.
    """

    points: np.ndarray
    mask: np.ndarray
    colors: np.ndarray | None = None

    @property
    def shape(self) -> tuple[int, int]:
        """Grid size (rows, columns)."""
        return self.points.shape[0], self.points.shape[1]

    def selected_indices(self) -> np.ndarray:
        """Flat indices of the points still of interest."""
        return np.flatnonzero(self.mask)

    def selected_points(self) -> np.ndarray:
        """Nx3 array of the points still of interest."""
        return self.points.reshape(-1, 3)[self.selected_indices()]

    def with_mask(self, mask: np.ndarray) -> PointCloud:
        """A new view sharing the points and colours but with another mask."""
        return PointCloud(points=self.points, mask=mask, colors=self.colors)


@dataclass(eq=False)
class Normals(View):
    """Per-point unit normals on the organized grid, HxWx3 float32 (NaN where unknown)."""

    normals: np.ndarray


@dataclass(eq=False)
class QueryView(View):
    """The perception query this CAS is answering (a ``queries.Query`` or any task description)."""

    query: object


@dataclass(eq=False)
class QueryAnswer(View):
    """The answer to this CAS's query, written by the step that answers it (e.g. a ``reasoning`` Answer)."""

    answer: object


# ----------------------------------------------------------------------------------------- annotations


@dataclass(eq=False, kw_only=True)
class Annotation(CasType):
    """Something an expert says; ``source`` names the annotator, ``confidence`` is in [0, 1].

    A type that states a categorical attribute of an object names it in ``attribute`` (the key of the fused
    attribute in beliefs, answers and belief filters) and reads its value in :meth:`attribute_value`; this is
    the one place that says which annotation type becomes which attribute. Which query keys a type answers and
    which ontology values it carries are said by the ontology (``rk:answeredBy``, ``rk:valueDomain``).
    """

    attribute: ClassVar[str] = ""
    """The object attribute this type states (``color``, ``class``, ...), empty when it states none."""

    source: str = ""
    confidence: float = 1.0

    def attribute_value(self) -> str:
        """The stated value of :attr:`attribute`, normalised for fusion (empty when the type states none)."""
        return ""


@dataclass(eq=False, kw_only=True)
class Plane(Annotation):
    """A plane a*x + b*y + c*z + d = 0 in the camera frame (unit normal pointing to the camera)."""

    model: np.ndarray
    inlier_indices: np.ndarray


@dataclass(eq=False, kw_only=True)
class ObjectHypothesis(Annotation):
    """A segment believed to be one object, with the annotations experts attached to it.

    ``point_indices`` are flat indices into the organized grid, ``mask`` is HxW bool and ``roi`` is the image
    box ``(x0, y0, x1, y1)`` of the mask in pixels, x1/y1 exclusive. The mask holds every point index; it may
    hold more pixels (a segmenter's claimed outline and foot), which the image experts see and the 3-D experts
    do not measure.
    """

    point_indices: np.ndarray
    mask: np.ndarray
    roi: tuple[int, int, int, int]
    annotations: list[Annotation] = field(default_factory=list)

    def find(self, annotation_type: type[A]) -> list[A]:
        """The attached annotations of this type or a subtype."""
        return [a for a in self.annotations if isinstance(a, annotation_type)]

    def first(self, annotation_type: type[A]) -> A | None:
        """The most confident attached annotation of this type, or None."""
        found = self.find(annotation_type)
        return max(found, key=lambda a: a.confidence) if found else None


@dataclass(eq=False, kw_only=True)
class PersonHypothesis(ObjectHypothesis):
    """An object hypothesis that is a person: its segment, plus the body keypoints and pose experts attach."""


PERSON_CLASS = "Human"
"""The ontology class a :class:`PersonHypothesis` is classified as (the class the query word "human" names)."""


@dataclass(eq=False, kw_only=True)
class BodyKeypoints(Annotation):
    """A person's body landmarks: ``names`` (N), image positions ``pixels`` (Nx2, pixels), camera-frame
    ``points`` (Nx3, metres, NaN where the cloud has no depth there) and ``visibility`` (N, 0..1)."""

    names: tuple[str, ...]
    pixels: np.ndarray
    points: np.ndarray
    visibility: np.ndarray


@dataclass(eq=False, kw_only=True)
class Activity(Annotation):
    """What a person is doing: ``activity`` (``pointing``, ``standing``, ``waving``) with the score of every
    activity considered (``scores``, 0..1) and, for pointing, the arm (``left`` / ``right``)."""

    activity: str
    scores: tuple[tuple[str, float], ...] = ()
    arm: str = ""


@dataclass(eq=False, kw_only=True)
class PointingTarget(Annotation):
    """What a person points at: ``kind`` (``object`` or ``region``), the ray (camera frame: ``origin``,
    unit ``direction``; ``second_direction`` the elbow-to-wrist estimate), the pointed object hypothesis' image
    box ``roi`` (objects) or the region's ``name`` (regions), the ``point`` aimed at (camera frame), the angle
    between the ray and that target (``angular_error``, radians), the angle between the two ray estimates
    (``spread``, radians) and the ``margin`` to the next-best candidate (radians)."""

    kind: str
    origin: np.ndarray
    direction: np.ndarray
    second_direction: np.ndarray
    point: np.ndarray
    angular_error: float
    spread: float
    margin: float
    name: str = ""
    roi: tuple[int, int, int, int] | None = None


@dataclass(eq=False, kw_only=True)
class SemanticColor(Annotation):
    """A colour name (an ontology colour class, lower case) with its share of the object's pixels."""

    attribute: ClassVar[str] = "color"

    color: str
    ratio: float = 1.0

    def attribute_value(self) -> str:
        """The colour name, lower case."""
        return self.color.strip().lower()


@dataclass(eq=False, kw_only=True)
class FormFeatures(Annotation):
    """What the object's form says for telling classes apart: its height over its width (upright), whether a
    handle sticks out of its side, whether it is open at the top (a cavity seen inside) and whether it is narrower
    across the middle of its height than across its top and bottom (a waist: a drill's grip between its body and
    battery), each yes/no with the evidence's confidence in [0, 1] (0: not seen). When the object stands on a thin
    wide base (a saucer, a plate, a coaster: :mod:`annotators.cloud.base_layer`), the cues are the body's above it
    and ``base_width`` and ``body_width`` (metres, the longer footprint extents) say so; both are None without a
    base."""

    height_to_width: float
    has_handle: bool
    handle_confidence: float
    open_top: bool
    open_confidence: float
    base_width: float | None = None
    body_width: float | None = None
    waisted: bool = False
    waist_confidence: float = 0.0


@dataclass(eq=False, kw_only=True)
class ColorHistogram(Annotation):
    """A normalised hue/saturation histogram of the object's pixels."""

    histogram: np.ndarray
    bins: tuple[int, ...]


@dataclass(eq=False, kw_only=True)
class Shape(Annotation):
    """A primitive shape: box, cylinder, sphere or flat."""

    attribute: ClassVar[str] = "shape"

    shape: str

    def attribute_value(self) -> str:
        """The shape name, lower case."""
        return self.shape.strip().lower()


@dataclass(eq=False, kw_only=True)
class Size(Annotation):
    """Metric extents (metres, sorted largest first) and a size class (small, medium, large)."""

    attribute: ClassVar[str] = "size"

    dimensions: tuple[float, float, float]
    size_class: str

    def attribute_value(self) -> str:
        """The size class, lower case."""
        return self.size_class.strip().lower()


@dataclass(eq=False, kw_only=True)
class Pose(Annotation):
    """An object pose: position and unit quaternion (x, y, z, w) in ``frame``."""

    position: np.ndarray
    orientation: np.ndarray
    frame: str = "camera"

    def matrix(self) -> np.ndarray:
        """The 4x4 homogeneous transform."""
        return pose_matrix(self.position, self.orientation)


@dataclass(eq=False, kw_only=True)
class Classification(Annotation):
    """An object class (the ontology class name, e.g. ``Milk``)."""

    attribute: ClassVar[str] = "class"

    class_name: str

    def attribute_value(self) -> str:
        """The class name as the ontology spells it."""
        return self.class_name.strip()


@dataclass(eq=False, kw_only=True)
class AnswersTo(Annotation):
    """That the object answers to the query's class as a whole (``class_name``, the class the query asked for),
    with the probability ``confidence``, when an expert named a class below it or packaged in it (a mustard for
    "find all bottles"). It says how well the object answers this query, not what the object is: the answer to
    the query shows it, the object's belief does not keep it (it states no attribute)."""

    class_name: str


@dataclass(eq=False, kw_only=True)
class Text(Annotation):
    """Text read on the object, with its image box ``(x0, y0, x1, y1)``."""

    attribute: ClassVar[str] = "text"

    text: str
    box: tuple[int, int, int, int] | None = None

    def attribute_value(self) -> str:
        """The text with its whitespace runs collapsed to single spaces."""
        return " ".join(self.text.split())


@dataclass(eq=False, kw_only=True)
class Location(Annotation):
    """The named semantic-map region the object is in (e.g. ``fridge``)."""

    attribute: ClassVar[str] = "region"

    region: str
    region_class: str = ""

    def attribute_value(self) -> str:
        """The region name, lower case."""
        return self.region.strip().lower()


@dataclass(eq=False, kw_only=True)
class TargetTrack(Annotation):
    """A continuous task's estimate of its one target in this frame (camera frame, metres).

    ``seen`` says whether a detection was associated with the target in this frame (``hypothesis``, None when
    not); ``position`` and ``velocity`` are the filtered estimate, ``pixel`` its image position (None when it
    is behind the camera), ``spread`` the estimate's standard deviation in metres, ``unseen_for`` the seconds
    since the target was last seen (0 when seen now) and ``target`` the class tracked ("" for any object).
    """

    target: str
    seen: bool
    position: np.ndarray
    velocity: np.ndarray
    pixel: tuple[float, float] | None
    spread: float
    unseen_for: float = 0.0
    hypothesis: ObjectHypothesis | None = None
    frame: str = "camera"


@dataclass(eq=False, kw_only=True)
class PersonTrack(TargetTrack):
    """The track of a person (from a people tracker)."""


@dataclass(eq=False, kw_only=True)
class FreePlacement(Annotation):
    """A free rectangle on a supporting surface where an object of the asked footprint can be put.

    ``position`` is the rectangle's centre on the surface and ``orientation`` (x, y, z, w) turns ``frame`` into
    the rectangle's axes (x along ``size[0]``, y along ``size[1]``, z the surface normal); ``size`` is the free
    extent (metres) and ``footprint`` the footprint asked for; ``fits`` is how many such footprints fit side by side.
    """

    position: np.ndarray
    orientation: np.ndarray
    size: tuple[float, float]
    footprint: tuple[float, float]
    frame: str = "camera"
    region: str = ""
    fits: int = 1


def _declared(root: type[T]) -> tuple[type[T], ...]:
    """The classes derived from ``root`` in this module, in declaration order."""
    found: list[type[T]] = []
    for cls in root.__subclasses__():
        if cls.__module__ == __name__:
            found += [cls, *_declared(cls)]
    return tuple(found)


VIEW_TYPES: tuple[type[View], ...] = _declared(View)
"""Every view type, in declaration order."""

ANNOTATION_TYPES: tuple[type[Annotation], ...] = _declared(Annotation)
"""Every annotation type, in declaration order."""

ATTRIBUTE_TYPES: tuple[type[Annotation], ...] = tuple(t for t in ANNOTATION_TYPES if t.attribute)
"""The annotation types that state an object attribute, in declaration order (the order of fused evidence)."""


def type_by_name(name: str) -> type[CasType]:
    """Look up a CAS type by its ontology name; raises KeyError listing the known names."""
    for cas_type in (CasType, View, Annotation, *VIEW_TYPES, *ANNOTATION_TYPES):
        if cas_type.__name__ == name:
            return cas_type
    known = ", ".join(t.__name__ for t in VIEW_TYPES + ANNOTATION_TYPES)
    raise KeyError(f"unknown CAS type {name!r}; known: {known}")


def attribute_type(attribute: str) -> type[Annotation]:
    """The annotation type that states ``attribute``; raises KeyError listing the attributes."""
    for annotation_type in ATTRIBUTE_TYPES:
        if annotation_type.attribute == attribute:
            return annotation_type
    known = ", ".join(t.attribute for t in ATTRIBUTE_TYPES)
    raise KeyError(f"no annotation type states the attribute {attribute!r}; known: {known}")
