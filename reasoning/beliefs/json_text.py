"""JSON text of the store's columns, made by one C encoder built once per format.

``json.JSONEncoder.encode`` builds the C encoder anew on every call (and ``json.dumps`` with options a whole
encoder); on the write path that set-up costs as much as the encoding of a small value. :class:`JsonText` builds it
once. The text is exactly what ``json.JSONEncoder(separators=...).encode`` gives for the same value.
:func:`parse_json` reads such text back with the C scanner directly, for the same reason.
"""

from __future__ import annotations

import json
import json.scanner
from collections.abc import Callable
from json import encoder as _encoder
from typing import Any


class JsonText:
    """``encode(value)`` is ``json.JSONEncoder(separators=(item_separator, key_separator)).encode(value)`` for
    values without reference cycles (the store's rows have none; cycles are not detected)."""

    def __init__(self, item_separator: str = ", ", key_separator: str = ": ") -> None:
        self._reference = json.JSONEncoder(separators=(item_separator, key_separator))
        self._fast: Callable[[Any, int], Any] | None = None
        make = getattr(_encoder, "c_make_encoder", None)
        if make is not None:
            try:
                self._fast = make(
                    None, self._reference.default, _encoder.encode_basestring_ascii, None,
                    key_separator, item_separator, False, False, True,
                )  # fmt: skip
            except TypeError:  # another signature in another Python: the reference encoder does it
                self._fast = None

    def encode(self, value: Any) -> str:
        """The JSON text of ``value``."""
        if self._fast is None or isinstance(value, str):
            return self._reference.encode(value)
        return "".join(self._fast(value, 0))


_C_SCANNER = getattr(json.scanner, "c_make_scanner", None)
_SCAN: Callable[[str, int], tuple[Any, int]] | None = None if _C_SCANNER is None else _C_SCANNER(json.JSONDecoder())


def parse_json(text: str) -> Any:
    """``json.loads(text)``, by the C scanner straight away when there is one (``json.loads`` wraps it in two Python
    calls that cost as much as parsing a short column); text it does not read whole is left to ``json.loads``."""
    if _SCAN is not None:
        try:
            value, end = _SCAN(text, 0)
        except StopIteration:
            pass
        else:
            if end == len(text):
                return value
    return json.loads(text)
