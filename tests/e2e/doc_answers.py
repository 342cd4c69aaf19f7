"""The answers the docs show under their curl examples (`# {...}` lines), read as patterns and matched against the
service's real answers: keys and shapes always, values as printed (to their last digit).

The docs abbreviate with `...`: `[...32 numbers...]` is an array of 32, `[[x,y], ... 50 points]` one of 50 items
shaped like the first, `[...5 curves of 7 points...]` 5 arrays of 7, `[0,0.0357, ...,1,1]` an array that starts and
ends so, `"version":...` any value, and `...` among an object's members more members than those shown.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from typing import Any

_TOKEN = re.compile(
    r'\s*(?:(?P<ell>\.\.\.(?:[^.,\]}]|\.(?!\.\.))*(?:\.\.\.)?)|(?P<str>"(?:[^"\\]|\\.)*")|(?P<num>-?\d+(?:\.\d+)?(?:[eE][+-]?\d+)?)'
    r"|(?P<word>[A-Za-z_]+)|(?P<punct>[{}\[\],:]))"
)


@dataclass
class Any_:
    """A value the docs leave out (`...`, `x`)."""

    what: str = ""


@dataclass
class Abbreviated:
    """An array shown in part: `head`, then (`count` items in all, `inner` items each where said) …, then `tail`."""

    head: list
    tail: list
    count: int | None
    inner: int | None


MORE = "..."  # an object's key: more members than those shown


def _tokens(text: str) -> list[tuple[str, str]]:
    out, pos = [], 0
    text = text.rstrip()
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None or m.end() == pos:
            break  # the rest of the line is a remark: "(503 until …)"
        out.append((m.lastgroup or "", m[m.lastgroup or 0].strip()))
        pos = m.end()
    return out


def parse(text: str) -> Any:
    """The documented answer `text` as a pattern: JSON values, Any_, Abbreviated and {MORE: …} objects."""
    tokens = _tokens(text)
    value, _ = _value(tokens, 0)
    return value


def _value(t: list[tuple[str, str]], i: int) -> tuple[Any, int]:
    kind, tok = t[i]
    if tok == "{":
        return _object(t, i + 1)
    if tok == "[":
        return _array(t, i + 1)
    if kind == "str":
        return json.loads(tok), i + 1
    if kind == "num":
        return Number(tok), i + 1
    if kind == "word":
        return {"true": True, "false": False, "null": None}.get(tok, Any_(tok)), i + 1
    if kind == "ell":
        return Any_(tok), i + 1
    raise ValueError(f"unexpected {tok!r}")


def _object(t: list[tuple[str, str]], i: int) -> tuple[dict, int]:
    out: dict[str, Any] = {}
    while t[i][1] != "}":
        if t[i][0] == "ell":
            out[MORE], i = Any_(), i + 1
        else:
            key = json.loads(t[i][1])
            out[key], i = _value(t, i + 2)  # past the key and its colon
        if t[i][1] == ",":
            i += 1
    return out, i + 1


def _array(t: list[tuple[str, str]], i: int) -> tuple[Any, int]:
    head: list = []
    tail: list = []
    ell = None
    while t[i][1] != "]":
        if t[i][0] == "ell":
            ell, i = t[i][1], i + 1
        else:
            item, i = _value(t, i)
            (tail if ell is not None else head).append(item)
        if t[i][1] == ",":
            i += 1
    if ell is None:
        return head, i + 1
    m = re.search(r"(\d+) \w+(?: of (\d+))?", ell)
    count, inner = (int(m[1]), int(m[2]) if m[2] else None) if m else (None, None)
    return Abbreviated(head, tail, count, inner), i + 1


@dataclass
class Number:
    """A number as printed: equal to an answer's to its last printed digit."""

    text: str

    def matches(self, value: Any) -> bool:
        if isinstance(value, bool) or not isinstance(value, int | float):
            return False
        decimals = len(self.text.split(".")[1].split("e")[0]) if "." in self.text else 0
        return abs(float(self.text) - value) <= 10.0**-decimals * 1.0001 + 1e-12 * abs(value)


def mismatches(pattern: Any, value: Any, where: str = "answer") -> list[str]:
    """Where `value` differs from the documented `pattern`: an empty list when it matches."""
    if isinstance(pattern, Any_):
        return []
    if isinstance(pattern, Number):
        return [] if pattern.matches(value) else [f"{where}: the docs say {pattern.text}, the service {value!r}"]
    if isinstance(pattern, dict):
        if not isinstance(value, dict):
            return [f"{where}: the docs show an object, the service {type(value).__name__}"]
        out = []
        shown = [k for k in pattern if k != MORE]
        missing = [k for k in shown if k not in value]
        extra = [k for k in value if k not in pattern] if MORE not in pattern else []
        if missing or extra:
            out.append(f"{where}: keys the docs show but the answer lacks {missing}, keys not shown {extra}")
        return out + [e for k in shown if k in value for e in mismatches(pattern[k], value[k], f"{where}.{k}")]
    if isinstance(pattern, list | Abbreviated):
        return _array_mismatches(pattern, value, where)
    return [] if pattern == value else [f"{where}: the docs say {pattern!r}, the service {value!r}"]


def _array_mismatches(pattern: list | Abbreviated, value: Any, where: str) -> list[str]:
    if not isinstance(value, list):
        return [f"{where}: the docs show an array, the service {type(value).__name__}"]
    if isinstance(pattern, list):
        if len(pattern) != len(value):
            return [f"{where}: the docs show {len(pattern)} items, the service {len(value)}"]
        return [e for i, (p, v) in enumerate(zip(pattern, value)) for e in mismatches(p, v, f"{where}[{i}]")]
    n = len(value)
    if (pattern.count is not None and n != pattern.count) or n < len(pattern.head) + len(pattern.tail):
        return [
            f"{where}: the docs show {pattern.count or 'at least ' + str(len(pattern.head))} items, the service {n}"
        ]
    out = [e for i, p in enumerate(pattern.head) for e in mismatches(p, value[i], f"{where}[{i}]")]
    out += [
        e
        for j, p in enumerate(pattern.tail)
        for e in mismatches(p, value[n - len(pattern.tail) + j], f"{where}[{n - len(pattern.tail) + j}]")
    ]
    like = pattern.head[0] if pattern.head else None
    for i, v in enumerate(value[len(pattern.head) : n - len(pattern.tail)], start=len(pattern.head)):
        out += _shape(like, v, f"{where}[{i}]") + (_count(pattern.inner, v, f"{where}[{i}]"))
    return out


def _count(inner: int | None, v: Any, where: str) -> list[str]:
    if inner is None or (isinstance(v, list) and len(v) == inner):
        return []
    return [f"{where}: the docs show {inner} items, the service {len(v) if isinstance(v, list) else v!r}"]


def _shape(like: Any, v: Any, where: str) -> list[str]:
    """The items an abbreviation stands for: shaped like the first one shown (arrays of its length, numbers)."""
    if like is None or isinstance(like, Any_):
        return []
    if isinstance(like, list):
        if not isinstance(v, list) or len(v) != len(like):
            return [f"{where}: shaped like {len(like)} items in the docs, the service {v!r:.60}"]
        return [e for i, (p, x) in enumerate(zip(like, v)) for e in _shape(p, x, f"{where}[{i}]")]
    if isinstance(like, Number):
        return [] if isinstance(v, int | float) and not isinstance(v, bool) else [f"{where}: a number in the docs"]
    if isinstance(like, dict):
        return [] if isinstance(v, dict) and all(k in v for k in like if k != MORE) else [f"{where}: keys differ"]
    return []
