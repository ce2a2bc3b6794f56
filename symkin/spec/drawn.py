"""The drawn layout: a mechanism written as it is drawn, turned into the local form.

With ``layout: drawn`` every point coordinate is global, in one assembled configuration. Each
body's frame is its first listed point with axes parallel to the global axes, or
``frame: {origin: POINT | [x, y], angle: EXPR}``; joints take ``at: POINT | [x, y]`` (or a
global ``sA``/``sB`` pair), prismatic and pin-slot joints ``axis: [dx, dy]``, the sliding
direction. From the drawing this module derives what the local form needs: every local vector
``s' = A(angle)^T (r - origin)``, the slide normal ``v`` (the axis turned by +90°, in body j),
``phi0`` (the frames' angle difference) and each body's ``q0`` = [origin, angle].

It works on the file's plain data, before the schema sees it, and builds expression *text*:
each piece of user text is first parsed alone by the whitelist parser (so that wrapping it in
parentheses cannot change its meaning) and is never evaluated by anything else. A piece that is
a plain number stays a number, so a numeric drawing gives a numeric local form.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass
from typing import Any

import yaml

from symkin import pairs
from symkin.errors import MechanismError
from symkin.limits import listed
from symkin.pairs.fields import GROUND
from symkin.pairs.kit import Joined, PairType
from symkin.spec import drawn_curves, drawn_slots, forces
from symkin.spec.drawn_quantities import Q, _Context, _neg, _numeric, _sub, _to_frame
from symkin.spec.schema import MechanismSpec

LAYOUTS = ("local", "drawn")
# The keys of inverse dynamics a drawn body may have besides points and frame.
DYNAMICS_KEYS = ("mass", "inertia", "com")

# Joint points that should coincide may differ by this much, relative to the drawing's size.
CLOSURE_TOLERANCE = 1e-6

Path_ = tuple[str | int, ...]


@dataclass(frozen=True)
class Frame:
    """A body's frame in the drawing: origin and angle."""

    x: Q
    y: Q
    angle: Q


# ----- the drawing ---------------------------------------------------------------------------

class Drawing:
    """The global points and frames of a drawn document."""

    def __init__(self, data: Mapping[str, Any]) -> None:
        self.context = _Context(data.get("parameters") or {})
        bodies = data.get("bodies")
        if not isinstance(bodies, Mapping) or not bodies:
            raise MechanismError("expected a mapping of bodies", ("bodies",))
        self.points: dict[str, dict[str, tuple[Q, Q]]] = {}
        self.frames: dict[str, Frame] = {GROUND: Frame(Q(0, 0.0), Q(0, 0.0), Q(0, 0.0))}
        for body, spec in bodies.items():
            self._body(str(body), spec)

    def _body(self, body: str, spec: Any) -> None:
        path: Path_ = ("bodies", body)
        if not isinstance(spec, Mapping):
            raise MechanismError("expected a mapping with points (and frame)", path)
        allowed = {"points"} if body == GROUND else {"points", "frame", *DYNAMICS_KEYS}
        for key in spec:
            if key not in allowed:
                hint = ("In the drawn layout q0 follows from the drawing: give the body's "
                        "frame with frame: {origin: POINT, angle: EXPR} instead."
                        if key == "q0" else f"Allowed keys here: {', '.join(sorted(allowed))}.")
                raise MechanismError(f"unknown key {key!r} in the drawn layout", path + (key,),
                                     hint)
        points = spec.get("points") or {}
        if not isinstance(points, Mapping):
            raise MechanismError("expected a mapping of point names to [x, y]",
                                 path + ("points",))
        self.points[body] = {str(name): self.context.vector(raw, path + ("points", name))
                             for name, raw in points.items()}
        if body != GROUND:
            self.frames[body] = self._frame(body, spec.get("frame"), path)

    def _frame(self, body: str, raw: Any, path: Path_) -> Frame:
        origin: Any = None
        angle = Q(0, 0.0)
        if raw is not None:
            if not isinstance(raw, Mapping) or set(raw) - {"origin", "angle"}:
                raise MechanismError("expected frame: {origin: POINT | [x, y], angle: EXPR}",
                                     path + ("frame",))
            origin = raw.get("origin")
            if "angle" in raw:
                angle = self.context.quantity(raw["angle"], path + ("frame", "angle"))
        if origin is None:
            if not self.points[body]:
                raise MechanismError(f"body {body!r} has no point to place its frame at",
                                     path, "List its points, or give frame: {origin: [x, y]}.")
            x, y = next(iter(self.points[body].values()))
        elif isinstance(origin, str):
            if origin not in self.points[body]:
                raise MechanismError(f"body {body!r} has no point named {origin!r}",
                                     path + ("frame", "origin"), "Name one of its points, or "
                                     "give global coordinates [x, y].")
            x, y = self.points[body][origin]
        else:
            x, y = self.context.vector(origin, path + ("frame", "origin"))
        return Frame(x, y, angle)

    def local(self, body: str, point: tuple[Q, Q]) -> tuple[Q, Q]:
        """A global point as a vector in the frame of ``body``."""
        frame = self.frames[body]
        return _to_frame(_sub(point[0], frame.x), _sub(point[1], frame.y), frame.angle)

    def q0(self, body: str) -> list[Any]:
        frame = self.frames[body]
        return [self.context.tidy(q) for q in (frame.x, frame.y, frame.angle)]

    def texts(self, vector: tuple[Q, Q]) -> list[Any]:
        return [self.context.tidy(vector[0]), self.context.tidy(vector[1])]

    # -- what a pair module asks of the drawing (symkin.pairs.kit.Drawing) ------------------
    def body(self, constraint: Mapping[str, Any], key: str, path: Path_) -> str:
        """The body a constraint's ``key`` names; an error naming the known ones."""
        body = constraint.get(key)
        if not isinstance(body, str) or body not in self.frames:
            known = listed(self.frames)
            raise MechanismError(f"unknown body {body!r}", path + (key,),
                                 f"Use one of: {known}.")
        return str(body)

    def point(self, body: str, raw: Any, path: Path_) -> tuple[Any, tuple[Q, Q]]:
        """A point given by name (on ``body``) or by global coordinates: (local ref, global)."""
        if isinstance(raw, str):
            if raw not in self.points.get(body, {}):
                known = listed(self.points.get(body, {})) or "none"
                raise MechanismError(f"body {body!r} has no point named {raw!r}", path,
                                     f"Its points are: {known}; or give global coordinates "
                                     "[x, y].")
            point = self.points[body][raw]
        else:
            point = self.context.vector(raw, path)
        if isinstance(raw, str) and body != GROUND:
            return raw, point
        return self.texts(self.local(body, point)), point

    def joined(self, data: Mapping[str, Any], path: Path_,
               keys: frozenset[str] = frozenset()) -> Joined:
        """Bodies i and j and their shared point, written with at: or a global sA and sB."""
        i, j = self.body(data, "i", path), self.body(data, "j", path)
        if "at" in data:
            if "sA" in data or "sB" in data:
                raise MechanismError("give either at: or sA and sB, not both", path + ("at",))
            at = data["at"]
            if isinstance(at, str):
                owners = [body for body in (i, j) if at in self.points.get(body, {})]
                if not owners:
                    raise MechanismError(f"neither {i!r} nor {j!r} has a point named {at!r}",
                                         path + ("at",), "Name a point of one of the two "
                                         "bodies, or give global coordinates [x, y].")
                drawn = self.points[owners[0]][at]
                a_raw = at if i in owners else [drawn[0].text, drawn[1].text]
                b_raw = at if j in owners else [drawn[0].text, drawn[1].text]
            else:
                a_raw = b_raw = at
            sA, A = self.point(i, a_raw, path + ("at",))
            sB, B = self.point(j, b_raw, path + ("at",))
        else:
            for key in ("sA", "sB"):
                if key not in data:
                    raise MechanismError("the joint's point is missing", path + ("at",),
                                         "Give at: POINT | [x, y] (or a global sA and sB).")
            sA, A = self.point(i, data["sA"], path + ("sA",))
            sB, B = self.point(j, data["sB"], path + ("sB",))
        local = {key: data[key] for key in ("type", "name", "i", "j") if key in data}
        local.update(sA=sA, sB=sB)
        return Joined(local, i, j, (A[0].value, A[1].value), (B[0].value, B[1].value))

    def slide_normal(self, joined: Joined, data: Mapping[str, Any],
                     path: Path_) -> tuple[list[Any], float]:
        """The slide's normal v (the drawn axis turned by +90 degrees, in body j's frame) and
        how far A lies off the slide through B."""
        if "axis" not in data:
            raise MechanismError(f"a {data.get('type')} joint needs axis: [dx, dy]",
                                 path + ("axis",), "Give the sliding direction as drawn, "
                                 "e.g. axis: [1, 0].")
        dx, dy = self.context.vector(data["axis"], path + ("axis",))
        length = math.hypot(dx.value, dy.value)
        if length == 0:
            raise MechanismError("the axis is zero", path + ("axis",), "Give a non-zero "
                                 "direction, e.g. [1, 0].")
        (ax, ay), (bx, by) = joined.A, joined.B
        gap = abs((bx - ax) * -dy.value + (by - ay) * dx.value) / length
        return self.texts(_to_frame(_neg(dy), dx, self.frames[joined.j].angle)), gap

    def direction(self, body: str, raw: Any, path: Path_) -> list[Any]:
        """A direction as drawn (global), in the frame of ``body``."""
        dx, dy = self.context.vector(raw, path)
        return self.texts(_to_frame(dx, dy, self.frames[body].angle))

    def curve(self, body: str, raw: Any, path: Path_) -> tuple[list[str], Any]:
        """A curve [x(s), y(s)] as drawn, in the frame of ``body`` that carries it."""
        frame = self.frames[body]
        return drawn_curves.in_frame(raw, (frame.x.text, frame.y.text), frame.angle.text,
                                     self._turned(body), self.context.symbols,
                                     self.context.values, path)

    def polar(self, body: str, rho: Any, path: Path_) -> Any:
        """A polar profile rho(s) as drawn, in the frame of ``body`` that carries it."""
        return drawn_curves.polar_in_frame(rho, self.frames[body].angle.text,
                                           self._turned(body), self.context.symbols, path)

    def _turned(self, body: str) -> bool:
        angle = self.frames[body].angle
        return not (_numeric(angle) and angle.value == 0)

    def value(self, raw: Any, path: Path_) -> float:
        """A drawn number or expression at the nominal parameters."""
        return self.context.quantity(raw, path).value

    def relative_angle(self, i: str, j: str) -> Any:
        """The angle of body i's frame less body j's, as drawn (a prismatic pair's phi0)."""
        return self.context.tidy(_sub(self.frames[i].angle, self.frames[j].angle))

    def size(self) -> float:
        """The drawing's largest coordinate magnitude (at least 1): the closure scale."""
        values = [abs(c.value) for pts in self.points.values() for p in pts.values() for c in p]
        return max([1.0, *values])


# ----- the local form ------------------------------------------------------------------------

def layout_of(data: Any) -> str:
    """The document's layout ('local' when the key is absent); an error for another value."""
    if not isinstance(data, Mapping) or "layout" not in data:
        return "local"
    layout = data["layout"]
    if layout not in LAYOUTS:
        raise MechanismError(f"unknown layout {layout!r}", ("layout",),
                             "Use layout: drawn (global coordinates as drawn) or leave the key "
                             "out (local vectors, the chapter's form).")
    return str(layout)


def to_local(data: Mapping[str, Any]) -> dict[str, Any]:
    """The local form of a document; a document without ``layout: drawn`` is returned as is."""
    local = {key: value for key, value in data.items() if key != "layout"}
    if layout_of(data) != "drawn":
        return local
    drawing = Drawing(data)

    def place(body: str, point: Any, path: Path_) -> Any:
        return drawing.point(body, point, path)[0]
    local["bodies"] = {body: {"q0": drawing.q0(body),
                              "points": {name: drawing.texts(drawing.local(body, point))
                                         for name, point in drawing.points[body].items()},
                              **body_dynamics(data["bodies"][body], body, place)}
                       for body in drawing.frames if body != GROUND}
    if "forces" in data:
        local["forces"] = [drawn_load(item, ("forces", index), drawing.frames, place)
                           for index, item in enumerate(_items(data, "forces"))]
    residuals = []
    for section in pairs.SECTIONS:
        converted = []
        for index, item in enumerate(_items(data, section)):
            item_local, residual = _constraint(drawing, item, (section, index))
            converted.append(item_local)
            if residual is not None:
                residuals.append((index, item, residual))
        local[section] = converted
    _check_closure(drawing, residuals)
    drawn_slots.name_slot_copies(data, local)
    return local


Place = Callable[[str, Any, Path_], Any]
"""(body, a point as drawn, its path) -> the point in the body's frame, as the file writes it."""


def body_dynamics(spec: Mapping[str, Any], body: str, place: Place) -> dict[str, Any]:
    """A drawn body's mass and inertia as written (its frame is parallel to the global axes,
    so a tensor as drawn is the one in its frame); its centre of mass in its own frame."""
    found = {key: spec[key] for key in DYNAMICS_KEYS if key in spec}
    if "com" in found:
        found["com"] = place(body, found["com"], ("bodies", body, "com"))
    return found


def drawn_load(item: Any, path: Path_, bodies: Collection[str], place: Place) -> Any:
    """A load with its points (drawn globally) in the frames of their bodies; unknown
    bodies and shapes go on to validation, which names them."""
    if not isinstance(item, Mapping):
        return item
    local = dict(item)
    for key, body_key in forces.POINT_KEYS.get(item.get("type"), ()):  # type: ignore[arg-type]
        body = item.get(body_key)
        if key in item and isinstance(body, str) and body in bodies:
            local[key] = place(body, item[key], path + (key,))
    return local


def _items(data: Mapping[str, Any], section: str) -> list[Any]:
    items = data.get(section) or []
    if not isinstance(items, list):
        raise MechanismError(f"expected a list of {section}", (section,))
    return items


def _constraint(drawing: Drawing, item: Any, path: Path_) -> tuple[Any, tuple[str, float] | None]:
    """One joint or driver in the local form, with its closure gap (label, size) if it has
    one. Shape errors go on to the schema as they are, which names them."""
    kind = pairs.named(item.get("type")) if isinstance(item, Mapping) else None
    if kind is None or path[0] not in kind.sections:
        return item, None
    extra = sorted(set(item) - kind.drawn_keys)
    if extra:
        hint = ("Give axis: [dx, dy], the sliding direction as drawn; v (the normal to the "
                "slide) and phi0 follow from the drawing." if extra[0] in ("v", "phi0") else
                f"A drawn {kind.name} has the keys {', '.join(sorted(kind.drawn_keys))}.")
        said = f"{extra[0]} is not used in the drawn layout" \
            if extra[0] in kind.model.model_fields else f"unknown key {extra[0]!r}"
        raise MechanismError(said, path + (extra[0],), hint)
    if kind.to_local is None:
        return _converted(drawing, kind, item, path), None
    local, gap = kind.to_local(item, drawing, path)
    bodies = "–".join(str(local.get(key)) for key in kind.bodies)
    return local, (None if gap is None else (f"{kind.name} {bodies}", gap))


def _converted(drawing: Drawing, kind: PairType, item: Mapping[str, Any],
               path: Path_) -> dict[str, Any]:
    """The generic conversion: each point to the local form of its body, each direction to
    its body's frame; everything else as written."""
    local = dict(item)
    for key, body_key in kind.points:
        body = drawing.body(item, body_key, path)
        if key not in item:
            raise MechanismError(f"the required key {key!r} is missing", path + (key,))
        local[key], _ = drawing.point(body, item[key], path + (key,))
    for key, body_key in kind.directions:
        if key in item:
            body = drawing.body(item, body_key, path)
            dx, dy = drawing.context.vector(item[key], path + (key,))
            local[key] = drawing.texts(_to_frame(dx, dy, drawing.frames[body].angle))
    return local


def _check_closure(drawing: Drawing, residuals: list[tuple[int, Any, tuple[str, float]]]) -> None:
    """Joint points that should coincide (or lie on the slide) must do so in the drawing."""
    tolerance = CLOSURE_TOLERANCE * drawing.size()
    open_joints = [(index, joint, label, gap) for index, joint, (label, gap) in residuals
                   if not gap <= tolerance]
    if not open_joints:
        return
    said = listed((f"joints[{index}]{' ' + repr(joint['name']) if joint.get('name') else ''}"
                   f" ({label}) is off by {gap:.6g}" for index, joint, label, gap in open_joints),
                  "; ")
    raise MechanismError(f"the drawing does not close: {said}", ("joints", open_joints[0][0]),
                         f"The two points of each joint must coincide (revolute) or lie on the "
                         f"slide (prismatic, pin_slot) or its curve at s0 (point_on_curve) "
                         f"within {tolerance:.3g}; correct their coordinates, or give the "
                         "joint one point with at:.")


def dump(mech: MechanismSpec) -> str:
    """A mechanism in the local layout as YAML text: a file ``symkin`` reads back unchanged."""
    data = mech.model_dump(mode="json", exclude_none=True)
    for section in pairs.SECTIONS:  # type first, then the keys in their model's order
        data[section] = [{"type": item["type"], **item} for item in data[section]]
    return str(yaml.safe_dump(data, sort_keys=False, default_flow_style=None, width=100,
                              allow_unicode=True))
