"""Matched beliefs updated on their stored rows: the common case of :meth:`BeliefTracker.update` followed by the
store's encoding of the belief, without decoding the row into an ``ObjectBelief`` first.

A stored ``objects`` row and the observation matched to it give the new row directly: the position filtered and
the size blended with Python floats (the same operations, in the same order, as the tracker's numpy ones), the
frame's statements accumulated into the packed supports with the rule of ``ValueSupport.add``, and the supports
packed again (a view that repeats the belief's last one as dependent evidence, :mod:`reasoning.fusion.views`).
The common case is: no colour histogram on either side, a 3-vector position, size and 4-vector
orientation in float64, every attribute single-valued before and after the update, and no named regions on the
tracker. Anything else goes the general way (decode, ``BeliefTracker.update``, encode); both ways give the same
row (``tests/fusion/test_row_update.py``). A new belief in the common case is made as a row the same way
(:meth:`RowUpdate.create`: the supports accumulated from none, the row ``BeliefTracker.create`` and the store's
encoding would give).

The supports are kept as :class:`Support` records in text space (attribute name, value, expert set) until they are
packed, so new texts are interned in the order the general encoder interns them (the same codes, the same file).
"""

from __future__ import annotations

import json
import sqlite3
from collections.abc import Callable, Sequence

import numpy as np

from reasoning.beliefs.interned import InternedTexts, decoded_supports
from reasoning.beliefs.packed import (
    INDEX_SEPARATOR,
    SUPPORT,
    decoded_sources,
    roi_from_text,
    roi_text,
    rounded_cached,
    supports_packing,
)
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import (
    CLASS_ATTRIBUTE,
    MAX_LOG_ODDS,
    AttributeBelief,
    ValueSupport,
    logit,
    repeated_log_odds,
)
from reasoning.fusion.tracking import PRESENT, BeliefTracker, ObjectBelief
from reasoning.fusion.views import repeats_view
from robokudo.core.types import Location

Support = list
"""One support of a stored belief while it is updated: [name code or None, value code or None, log-odds (not
rounded), count, expert-set code or None, first seen, last seen, name, value, expert names]; a code is None when it
is still to be interned (a new text or a new expert set)."""

_SUPPORT_NAME, _SUPPORT_VALUE, _SUPPORT_EXPERTS = 7, 8, 9
LOGIT_CACHE_LIMIT = 4096
"""Distinct confidences whose log-odds a :class:`RowUpdate` remembers (beyond that it starts afresh)."""


_FLOAT64 = np.dtype(np.float64)


def _is_vector(values: object, length: int) -> bool:
    """True when ``values`` is a float64 array of shape ``(length,)`` (another float64 descriptor object than numpy's
    own only sends the update the general way)."""
    return type(values) is np.ndarray and values.dtype is _FLOAT64 and values.shape == (length,)


class RowUpdate:
    """The row-level update of one store connection (see the module docstring).

    ``sources`` caches the JSON of expert sets by (stored text, stated experts); it holds texts only, so it stays
    right after a rollback (codes are never cached here beyond :class:`InternedTexts`, which forgets them).
    """

    def __init__(self, tracker: BeliefTracker, interned: InternedTexts, conn: sqlite3.Connection) -> None:
        self.config = tracker.config
        self.interned = interned
        self.conn = conn
        self.sources: dict[tuple[str, frozenset[str]], str] = {}
        self.logits: dict[float, float] = {}
        """``logit`` of the confidences met (few distinct values recur on every frame)."""

    @staticmethod
    def applies(tracker: BeliefTracker) -> bool:
        """True when ``tracker`` updates beliefs as this module does (the plain tracker, no named regions)."""
        return type(tracker) is BeliefTracker and not tracker.regions

    def supports(self, row: tuple) -> list[Support]:
        """The supports of a stored row, in stored order (texts read from ``interned``)."""
        return [list(decoded) for decoded in decoded_supports(row[26], SUPPORT, self.interned, self.conn)]

    def update(self, row: tuple, records: list[Support], observation: FrameObject, time: float) -> tuple | None:
        """The new ``objects`` row of ``row`` (its supports ``records``) updated by ``observation`` at ``time``, or
        None when that is not the common case (then nothing was changed). ``records`` are updated in place; the
        row's attribute column is left None: :meth:`pack` fills it, in write order."""
        if row[14] is not None or observation.appearance is not None:
            return None
        if not (
            _is_vector(observation.position, 3)
            and _is_vector(observation.orientation, 4)
            and _is_vector(observation.dimensions, 3)
        ):
            return None
        by_name: dict[str, Support] = {}
        for r in records:
            if r[_SUPPORT_NAME] in by_name:
                return None  # a multi-valued attribute
            by_name[r[_SUPPORT_NAME]] = r
        stated: dict[str, str] = {}
        for e in observation.evidence:
            r = by_name.get(e.attribute)
            if (r[_SUPPORT_VALUE] if r is not None else stated.setdefault(e.attribute, e.value)) != e.value:
                return None  # a second value stated
        (object_id, _, frame, px, py, pz, _, _, _, _, sx, sy, sz, variance, appearance, existence, _, first_seen,
         last_seen, _, observations, _, _, recording, last_roi, sources, _, _) = row[:28]  # fmt: skip
        roi = roi_text(observation.roi)
        repeated = (
            roi is not None
            and last_roi is not None
            and frame == observation.frame
            and recording == observation.recording
            and (
                roi == last_roi
                or repeats_view(roi_from_text(last_roi), frame, recording, observation.roi, frame, recording)
            )
        )
        if repeated:
            self._repeat(by_name, records, observation, time)
        else:
            self._accumulate(by_name, records, observation, time)
        config = self.config
        predicted = variance + config.motion_sigma**2 * max(time - last_seen, 0.0)
        gain = predicted / (predicted + config.measurement_sigma**2 / max(observation.confidence, 0.1))
        x, y, z = observation.position.tolist()
        a, b, c = observation.dimensions.tolist()  # type: ignore[union-attr]
        if sx is not None:
            rate = config.blend_rate
            a, b, c = (1.0 - rate) * sx + rate * a, (1.0 - rate) * sy + rate * b, (1.0 - rate) * sz + rate * c
        class_name, region, entries = _class_region_entries(records)
        stated = frozenset(observation.sources)
        text = self.sources.get((sources, stated))
        if text is None:
            text = self.sources[(sources, stated)] = json.dumps(sorted({*decoded_sources(sources), *stated}))
        qx, qy, qz, qw = observation.orientation.tolist()  # floats(orientation, 4) of a float64 4-vector
        return (
            object_id,
            class_name,
            frame,
            px + gain * (x - px),
            py + gain * (y - py),
            pz + gain * (z - pz),
            qx,
            qy,
            qz,
            qw,
            a,
            b,
            c,
            (1.0 - gain) * predicted,
            appearance,
            max(existence, config.hit_log_odds) if repeated else min(existence + config.hit_log_odds, MAX_LOG_ODDS),
            PRESENT,
            first_seen,
            float(max(last_seen, time)),
            0,
            observations + 1,
            region or "",
            "",
            recording,
            roi,
            text,
            None,
            INDEX_SEPARATOR.join(sorted(entries)),
        )

    def _accumulate(
        self, by_name: dict[str, Support], records: list[Support], observation: FrameObject, time: float
    ) -> None:
        """``ValueSupport.add`` of each of the observation's statements at ``time`` into the single-valued supports
        ``by_name`` (a new attribute's support appended to ``records``)."""
        logits = self.logits
        if len(logits) > LOGIT_CACHE_LIMIT:
            logits.clear()
        for e in observation.evidence:
            r = by_name.get(e.attribute)
            if r is None:
                r = by_name[e.attribute] = [None, None, 0.0, 0, None, 0.0, 0.0, e.attribute, e.value, ()]
                records.append(r)
            if r[3] == 0 or time < r[5]:
                r[5] = time
            confidence = e.confidence
            log_odds = logits.get(confidence)
            if log_odds is None:
                log_odds = logits[confidence] = logit(confidence)
            total = r[2] + log_odds
            total = -MAX_LOG_ODDS if total < -MAX_LOG_ODDS else total
            r[2] = MAX_LOG_ODDS if total > MAX_LOG_ODDS else total
            r[3] += 1
            if e.source not in r[_SUPPORT_EXPERTS]:
                r[_SUPPORT_EXPERTS] = (*r[_SUPPORT_EXPERTS], e.source)
                r[4] = None
            if r[6] < time:
                r[6] = time

    def _repeat(
        self, by_name: dict[str, Support], records: list[Support], observation: FrameObject, time: float
    ) -> None:
        """``ValueSupport.repeat`` of the observation's statements (summed per attribute: one value each here) at
        ``time`` into the single-valued supports ``by_name``: a view that repeats the belief's last one.

        Written out like :meth:`_accumulate` (the support lookup and the experts' credit repeat there): shared
        through two helper functions, the two methods ran 1.46x and 1.16x slower (in-process A/B, 2026-11-28) on
        the path every matched belief takes."""
        logits = self.logits
        if len(logits) > LOGIT_CACHE_LIMIT:
            logits.clear()
        said: dict[str, list] = {}
        for e in observation.evidence:
            log_odds = logits.get(e.confidence)
            if log_odds is None:
                log_odds = logits[e.confidence] = logit(e.confidence)
            held = said.get(e.attribute)
            if held is None:
                said[e.attribute] = [log_odds, [e.source], e.value]
            else:
                held[0] += log_odds
                held[1].append(e.source)
        for name, (log_odds, sources, value) in said.items():
            r = by_name.get(name)
            if r is None:
                r = by_name[name] = [None, None, 0.0, 0, None, 0.0, 0.0, name, value, ()]
                records.append(r)
            if r[3] == 0 or time < r[5]:
                r[5] = time
            bounded = (
                -MAX_LOG_ODDS if log_odds < -MAX_LOG_ODDS else MAX_LOG_ODDS if log_odds > MAX_LOG_ODDS else log_odds
            )
            r[2] = repeated_log_odds(r[2], bounded)
            r[3] += len(sources)
            for source in sources:
                if source not in r[_SUPPORT_EXPERTS]:
                    r[_SUPPORT_EXPERTS] = (*r[_SUPPORT_EXPERTS], source)
                    r[4] = None
            if r[6] < time:
                r[6] = time

    def create(self, observation: FrameObject, time: float, belief_id: int) -> tuple[tuple, list[Support]] | None:
        """The ``objects`` row and supports of the belief ``BeliefTracker.create`` makes of ``observation`` (id
        ``belief_id``, first seen at ``time``), or None when that is not the common case (no histogram, float64
        3-vector position and size, 4-vector orientation, one value stated per attribute). The attribute column is
        left None: :meth:`pack` fills it, in write order."""
        if observation.appearance is not None or not (
            _is_vector(observation.position, 3)
            and _is_vector(observation.orientation, 4)
            and _is_vector(observation.dimensions, 3)
        ):
            return None
        stated: dict[str, str] = {}
        for e in observation.evidence:
            if stated.setdefault(e.attribute, e.value) != e.value:
                return None  # a second value stated
        records: list[Support] = []
        self._accumulate({}, records, observation, time)
        class_name, region, entries = _class_region_entries(records)
        experts = frozenset(observation.sources)
        text = self.sources.get(("[]", experts))  # an empty stored set joined with the stated experts
        if text is None:
            text = self.sources[("[]", experts)] = json.dumps(sorted(experts))
        config = self.config
        seen = float(time)
        return (
            belief_id,
            class_name,
            observation.frame,
            *observation.position.tolist(),
            *observation.orientation.tolist(),
            *observation.dimensions.tolist(),  # type: ignore[union-attr]
            float(config.measurement_sigma**2 / max(observation.confidence, 0.1)),
            None,
            float(min(logit(observation.confidence), config.hit_log_odds)),
            PRESENT,
            seen,
            seen,
            0,
            1,
            region or "",
            "",
            observation.recording,
            roi_text(observation.roi),
            text,
            None,
            INDEX_SEPARATOR.join(sorted(entries)),
        ), records

    def pack(self, row: tuple, records: Sequence[Support], write: Callable[[str, list[tuple]], None]) -> tuple:
        """``row`` with its attribute column packed from ``records`` (texts new to the store interned with
        ``write``, in the order of the records: name, value, experts)."""
        interned, conn = self.interned, self.conn
        codes, expert_codes = interned.codes, interned.expert_codes
        flat: list = []
        for r in records:
            name_code, value_code, log_odds, count, experts, first_seen, last_seen, name, value, names = r
            if name_code is None:
                name_code = codes.get(name)
                if name_code is None:
                    name_code = interned.code(conn, name, write)
            if value_code is None:
                value_code = codes.get(value)
                if value_code is None:
                    value_code = interned.code(conn, value, write)
            if experts is None:
                experts = expert_codes.get(frozenset(names))
                if experts is None:
                    experts = interned.experts_code(conn, set(names), write)
            rounded = rounded_cached(log_odds, 9) if log_odds else round(log_odds, 9)
            flat += (name_code, value_code, rounded, count, experts, first_seen, last_seen)
        return (*row[:26], supports_packing(len(records)).pack(*flat), row[27])


def _class_region_entries(records: Sequence[Support]) -> tuple[str | None, str | None, list[str]]:
    """The class (when its support is positive), the region and the index entries (``name=value``) of single-valued
    supports."""
    class_name = region = None
    entries = []
    for r in records:
        name, value = r[_SUPPORT_NAME], r[_SUPPORT_VALUE]
        if name == CLASS_ATTRIBUTE:
            class_name = value if r[2] > 0 else None
        elif name == Location.attribute:
            region = value
        entries.append(f"{name}={value}")
    return class_name, region, entries


def belief_of(row: tuple, records: Sequence[Support], roi: tuple[int, int, int, int] | None) -> ObjectBelief:
    """The ``ObjectBelief`` a row-level update stands for: the new row, the supports with their log-odds not rounded,
    and the observation's image box as given (what ``BeliefTracker.update`` leaves in the belief)."""
    attributes: dict[str, AttributeBelief] = {}
    for r in records:
        name = r[_SUPPORT_NAME]
        attributes[name] = AttributeBelief(
            name, {r[_SUPPORT_VALUE]: ValueSupport(r[2], r[3], set(r[_SUPPORT_EXPERTS]), r[5], r[6])}
        )
    return ObjectBelief(
        id=row[0],
        frame=row[2],
        position=np.array(row[3:6]),
        orientation=np.array(row[6:10]),
        dimensions=np.array(row[10:13]),
        appearance=None,
        attributes=attributes,
        position_variance=row[13],
        existence=row[15],
        status=row[16],
        first_seen=row[17],
        last_seen=row[18],
        misses=row[19],
        region=row[21],
        region_class=row[22],
        roi=roi,
        sources=set(decoded_sources(row[25])),
        observations=row[20],
        class_name=row[1],
        recording=row[23],
    )
