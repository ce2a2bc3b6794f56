"""The drawn layout's shared points of sliding pairs. A pin-in-slot (or prismatic) pair drawn
with ``at: A``, where both bodies list a point ``A``, joins two different material points:
the pin's A moves along the slot, while the slotted body's copy stays where it was drawn on
that body. Reported under one name they look like one point that came apart; so the slotted
body's (j's) copy is renamed ``A@slot`` in the local form — in its body's points and in every
reference to it — and reads ``lever.A@slot`` in results, plots and reports.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from symkin import pairs
from symkin.pairs.fields import GROUND
from symkin.spec.names import SLOT_SUFFIX


def _points(data: Mapping[str, Any], body: Any) -> Mapping[str, Any]:
    spec = (data.get("bodies") or {}).get(body)
    points = spec.get("points") if isinstance(spec, Mapping) else None
    return points if isinstance(points, Mapping) else {}


def _renames(data: Mapping[str, Any]) -> dict[tuple[str, str], str]:
    """(slotted body, point) -> new name, for each sliding pair drawn with at: NAME that
    both its bodies list."""
    found: dict[tuple[str, str], str] = {}
    for section in pairs.SECTIONS:
        for item in data.get(section) or []:
            kind = pairs.named(item.get("type")) if isinstance(item, Mapping) else None
            if kind is None or kind.slide is None or not isinstance(item.get("at"), str):
                continue
            i, j, at = item.get("i"), item.get("j"), item["at"]
            if j != GROUND and at in _points(data, j) and at in _points(data, i):
                found[(str(j), at)] = at + SLOT_SUFFIX
    return found


def name_slot_copies(data: Mapping[str, Any], local: dict[str, Any]) -> None:
    """Rename, in ``local`` (the local form of the drawn ``data``), the slotted body's copy
    of each shared point of a sliding pair, and every reference to it."""
    renames = _renames(data)
    for (body, old), new in renames.items():
        points = local["bodies"][body]["points"]
        local["bodies"][body]["points"] = {new if name == old else name: vector
                                           for name, vector in points.items()}
    for section in pairs.SECTIONS:
        for item in local.get(section) or []:
            kind = pairs.named(item.get("type")) if isinstance(item, Mapping) else None
            for key, body_key in kind.points if kind is not None and renames else ():
                ref = item.get(key)
                if isinstance(ref, str) and (item.get(body_key), ref) in renames:
                    item[key] = renames[(item.get(body_key), ref)]
