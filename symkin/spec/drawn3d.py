"""The drawn layout of a spatial file (``space: 3d``), turned into the local form.

Every coordinate is global, as drawn at t0: points are [x, y, z], shared point names join
bodies. Each body's frame sits at its first point (or ``frame: {origin: POINT | [x, y, z]}``)
with axes parallel to the global ones, so its q0 is [origin, 1, 0, 0, 0] (identity Euler
parameters), its local vectors are the drawn points less the origin, and a direction fixed in
a body is the drawn direction itself. Like :mod:`symkin.spec.drawn` it builds expression text
from pieces each parsed alone by the whitelist parser.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from symkin import pairs
from symkin.errors import MechanismError
from symkin.limits import listed
from symkin.pairs.fields import GROUND
from symkin.spec.drawn import DYNAMICS_KEYS, body_dynamics, drawn_load, layout_of
from symkin.spec.drawn_quantities import Q, _Context, _sub

SPACES = ("2d", "3d")
Vector = tuple[Q, Q, Q]
Path_ = tuple[str | int, ...]


def space_of(data: Any) -> str:
    """The document's space ('2d' when the key is absent); an error for another value."""
    if not isinstance(data, Mapping) or "space" not in data:
        return "2d"
    if data["space"] not in SPACES:
        raise MechanismError(f"unknown space {data['space']!r}", ("space",),
                             "Use space: 3d for a spatial mechanism, or leave the key out "
                             "(a planar one).")
    return str(data["space"])


class Drawing3d:
    """The global points and frame origins of a spatial drawing; what a spatial pair module's
    ``to_local`` is given (:class:`symkin.pairs.spatial.basic.Drawing`)."""

    def __init__(self, data: Mapping[str, Any]) -> None:
        self.context = _Context(data.get("parameters") or {})
        bodies = data.get("bodies")
        if not isinstance(bodies, Mapping) or not bodies:
            raise MechanismError("expected a mapping of bodies", ("bodies",))
        zero = Q(0, 0.0)
        self.points: dict[str, dict[str, Vector]] = {GROUND: {}}
        self.origins: dict[str, Vector] = {GROUND: (zero, zero, zero)}
        for body, spec in bodies.items():
            self._body(str(body), spec)
        self.joints = {item.get("name"): (item, ("joints", k))
                       for k, item in enumerate(data.get("joints") or [])
                       if isinstance(item, Mapping) and isinstance(item.get("name"), str)}

    def _body(self, body: str, spec: Any) -> None:
        path: Path_ = ("bodies", body)
        if not isinstance(spec, Mapping):
            raise MechanismError("expected a mapping with points (and frame)", path)
        allowed = {"points"} if body == GROUND else {"points", "frame", *DYNAMICS_KEYS}
        for key in spec:
            if key not in allowed:
                raise MechanismError(f"unknown key {key!r} in the drawn layout", path + (key,),
                                     f"Allowed keys here: {', '.join(sorted(allowed))}.")
        points = spec.get("points") or {}
        if not isinstance(points, Mapping):
            raise MechanismError("expected a mapping of point names to [x, y, z]",
                                 path + ("points",))
        self.points[body] = {str(name): self.vector(raw, path + ("points", name))
                             for name, raw in points.items()}
        if body != GROUND:
            self.origins[body] = self._origin(body, spec.get("frame"), path + ("frame",))

    def _origin(self, body: str, raw: Any, path: Path_) -> Vector:
        if raw is None:
            if not self.points[body]:
                raise MechanismError(f"body {body!r} has no point to place its frame at",
                                     path[:-1], "List its points, or give frame: "
                                     "{origin: [x, y, z]}.")
            return next(iter(self.points[body].values()))
        if not isinstance(raw, Mapping) or set(raw) != {"origin"}:
            raise MechanismError("expected frame: {origin: POINT | [x, y, z]}", path,
                                 "A spatial body's frame is parallel to the global axes as "
                                 "drawn: give only its origin.")
        origin = raw["origin"]
        if isinstance(origin, str):
            if origin not in self.points[body]:
                raise MechanismError(f"body {body!r} has no point named {origin!r}",
                                     path + ("origin",), "Name one of its points, or give "
                                     "global coordinates [x, y, z].")
            return self.points[body][origin]
        return self.vector(origin, path + ("origin",))

    def vector(self, raw: Any, path: Path_) -> Vector:
        if not isinstance(raw, (list, tuple)) or len(raw) != 3:
            got = f"{len(raw)} numbers" if isinstance(raw, (list, tuple)) else "no list"
            raise MechanismError(f"expected a vector [x, y, z] in a 3d file, got {got}", path,
                                 "Every point and direction of a space: 3d file has three "
                                 "coordinates.")
        x, y, z = (self.context.quantity(item, path + (k,)) for k, item in enumerate(raw))
        return x, y, z

    def texts(self, vector: Sequence[Q]) -> list[Any]:
        return [self.context.tidy(q) for q in vector]

    def local(self, body: str, point: Vector) -> list[Any]:
        """A global point as a vector in the frame of ``body`` (parallel to the global one)."""
        return self.texts(tuple(_sub(p, o) for p, o in zip(point, self.origins[body])))

    def q0(self, body: str) -> list[Any]:
        return [*self.texts(self.origins[body]), 1, 0, 0, 0]

    # -- what a spatial pair module asks (symkin.pairs.spatial.basic.Drawing) --------------
    def body(self, data: Any, key: str, path: Path_) -> str:
        body = data.get(key)
        if not isinstance(body, str) or body not in self.origins:
            raise MechanismError(f"unknown body {body!r}", path + (key,),
                                 f"Use one of: {listed(self.origins)}.")
        return str(body)

    def point(self, body: str, raw: Any, path: Path_) -> Any:
        """A point by name (kept: the local form has the body's points) or global [x, y, z]."""
        if isinstance(raw, str):
            if raw not in self.points[body]:
                known = listed(self.points[body]) or "none"
                raise MechanismError(f"body {body!r} has no point named {raw!r}", path,
                                     f"Its points are: {known}; or give global coordinates "
                                     "[x, y, z].")
            return raw if body != GROUND else self.local(body, self.points[body][raw])
        return self.local(body, self.vector(raw, path))

    def joined(self, data: Any, path: Path_) -> dict[str, Any]:
        """type, name, i, j and the joint's point ``at`` local in i (sA) and in j (sB)."""
        i, j = self.body(data, "i", path), self.body(data, "j", path)
        if "at" not in data:
            raise MechanismError("the joint's point is missing", path + ("at",),
                                 "Give at: POINT | [x, y, z].")
        at = data["at"]
        if isinstance(at, str):
            owners = [body for body in (i, j) if at in self.points[body]]
            if not owners:
                raise MechanismError(f"neither {i!r} nor {j!r} has a point named {at!r}",
                                     path + ("at",), "Name a point of one of the two bodies, "
                                     "or give global coordinates [x, y, z].")
            drawn = self.points[owners[0]][at]
            if len(owners) == 2 and any(a.value != b.value
                                        for a, b in zip(drawn, self.points[owners[1]][at])):
                raise MechanismError(f"the point {at!r} is drawn at different places on "
                                     f"{i!r} and {j!r}", path + ("at",),
                                     "A shared point name means one point: draw it once.")
            sA = self.point(i, at, path) if i in owners else self.local(i, drawn)
            sB = self.point(j, at, path) if j in owners else self.local(j, drawn)
        else:
            point = self.vector(at, path + ("at",))
            sA, sB = self.local(i, point), self.local(j, point)
        local = {key: data[key] for key in ("type", "name", "i", "j") if key in data}
        local.update(sA=sA, sB=sB)
        return local

    def direction(self, raw: Any, path: Path_) -> list[Any]:
        """A direction as drawn (the same in every body's frame); never zero."""
        if raw is None:
            raise MechanismError("the axis is missing", path, "Give the direction as drawn, "
                                 "e.g. axis: [0, 0, 1].")
        vector = self.vector(raw, path)
        if math.hypot(*(q.value for q in vector)) == 0:
            raise MechanismError("the axis is zero", path, "Give a non-zero direction, e.g. "
                                 "[0, 0, 1].")
        return self.texts(vector)

    def joint(self, name: Any, path: Path_, kinds: tuple[str, ...]) -> dict[str, Any]:
        """The local form of the joint called ``name``, which must be one of ``kinds``."""
        if not isinstance(name, str) or name not in self.joints:
            known = listed(map(str, self.joints)) or "none"
            raise MechanismError(f"no joint named {name!r}", path,
                                 f"Name a {' or '.join(kinds)} joint; the named joints are: "
                                 f"{known}.")
        item, where = self.joints[name]
        if item.get("type") not in kinds:
            raise MechanismError(f"joint {name!r} is a {item.get('type')}, which has no axis "
                                 "to drive", path, f"Name a {' or '.join(kinds)} joint.")
        kind = pairs.named_in(item.get("type"), "joints", "3d")
        assert kind is not None and kind.to_local is not None  # a type of `kinds`
        local, _ = kind.to_local(item, self, where)
        return local


def to_local(data: Mapping[str, Any]) -> dict[str, Any]:
    """The local form of a spatial document (a local-layout one is returned as is)."""
    local = {key: value for key, value in data.items() if key != "layout"}
    if layout_of(data) != "drawn":
        return local
    drawing = Drawing3d(data)
    local["bodies"] = {body: {"q0": drawing.q0(body),
                              "points": {name: drawing.local(body, point)
                                         for name, point in drawing.points[body].items()},
                              **body_dynamics(data["bodies"][body], body, drawing.point)}
                       for body in drawing.origins if body != GROUND}
    if "forces" in data:
        local["forces"] = [drawn_load(item, ("forces", index), drawing.origins, drawing.point)
                           for index, item in enumerate(_items(data, "forces"))]
    for section in pairs.SECTIONS:
        items = data.get(section) or []
        if not isinstance(items, list):
            raise MechanismError(f"expected a list of {section}", (section,))
        local[section] = [_constraint(drawing, item, (section, k))
                          for k, item in enumerate(items)]
    return local


def _items(data: Mapping[str, Any], section: str) -> list[Any]:
    items = data.get(section) or []
    if not isinstance(items, list):
        raise MechanismError(f"expected a list of {section}", (section,))
    return items


def _constraint(drawing: Drawing3d, item: Any, path: Path_) -> Any:
    """One joint or driver in the local form; shape errors go on to the schema as they are."""
    section = str(path[0])
    kind = pairs.named_in(item.get("type"), section, "3d") \
        if isinstance(item, Mapping) else None
    if kind is None:
        if isinstance(item, Mapping) and isinstance(item.get("type"), str):
            listed = ", ".join(k.name for k in pairs.in_section(section, "3d"))
            raise MechanismError(f"{item['type']!r} is not a type of a space: 3d file's "
                                 f"{section}", path + ("type",), f"Use one of: {listed}.")
        return item
    extra = sorted(set(item) - kind.drawn_keys)
    if extra:
        raise MechanismError(f"unknown key {extra[0]!r}", path + (extra[0],),
                             f"A drawn spatial {kind.name} has the keys "
                             f"{', '.join(sorted(kind.drawn_keys))}.")
    if kind.to_local is None:
        return item
    local, _ = kind.to_local(item, drawing, path)
    return local
