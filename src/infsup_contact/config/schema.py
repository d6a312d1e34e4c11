"""A workflow config against its schema: the one-line :class:`ConfigError`, the key paths it
names, non-finite numbers, and the JSON schema's violations in words; a request's own field
check run under a config key (:func:`naming_key`).

:mod:`infsup_contact.config.checks` runs these first and then the checks a schema cannot
state; pure functions, no Snakemake.
"""
from __future__ import annotations

import math
from contextlib import contextmanager
from pathlib import Path


class ConfigError(ValueError):
    """A bad config value; the message is one line naming the key."""

    def __init__(self, key: str, what: str, got=None, allowed: str | None = None):
        self.key = key
        detail = "; ".join(p for p in (None if got is None else f"got {show(got)}",
                                       None if allowed is None else f"allowed {allowed}") if p)
        super().__init__(f"config key {key}: {what}" + (f" ({detail})" if detail else ""))


@contextmanager
def naming_key(key: str, what: str, got=None, allowed: str | None = None):
    """Run the rule a request field has (:mod:`infsup_contact.solvers.request`, the registry) on a
    config value: its :class:`~infsup_contact.errors.InputError` becomes one :class:`ConfigError`
    naming the config ``key`` in the config's words ``what`` (``got``, ``allowed``: default the
    error's own), so a field has one rule and its message names the key the user wrote."""
    from ..errors import InputError

    try:
        yield
    except InputError as err:
        raise ConfigError(key, what, got=err.got if got is None else got,
                          allowed=err.allowed if allowed is None else allowed) from None


def show(value, limit: int = 80) -> str:
    """A short one-line repr of a config value."""
    text = value if isinstance(value, str) and value.startswith("<") else repr(value)
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[: limit - 1] + "…"


def key_path(path) -> str:
    """``("infsup", "N", 0)`` → ``infsup.N[0]``."""
    out = ""
    for part in path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out or "(top level)"


# ------------------------------------------------------------------ 2. non-finite numbers

def check_finite(node, path=()) -> None:
    """No ``.nan``/``.inf`` anywhere: a JSON schema's ``minimum`` lets NaN pass."""
    if isinstance(node, float) and not math.isfinite(node):
        raise ConfigError(key_path(path), "not a finite number", got=node,
                          allowed="finite numbers only (.nan and .inf mean nothing in any key)")
    if isinstance(node, dict):
        for key, value in node.items():
            check_finite(value, (*path, key))
    elif isinstance(node, list):
        for i, value in enumerate(node):
            check_finite(value, (*path, i))


# ------------------------------------------------------------------ 3. the schema

def load_schema(path) -> dict:
    from ..yaml_limits import load

    return load(Path(path).read_text())


def _resolve(schema: dict, root: dict) -> dict:
    ref = schema.get("$ref") if isinstance(schema, dict) else None
    if ref and ref.startswith("#/"):
        node = root
        for part in ref[2:].split("/"):
            node = node[part]
        return _resolve(node, root)
    return schema if isinstance(schema, dict) else {}


def _number_range(s: dict) -> str:
    lo = (f">= {s['minimum']}" if "minimum" in s else
          f"> {s['exclusiveMinimum']}" if "exclusiveMinimum" in s else "")
    hi = (f"<= {s['maximum']}" if "maximum" in s else
          f"< {s['exclusiveMaximum']}" if "exclusiveMaximum" in s else "")
    if "minimum" in s and "maximum" in s:
        return f" in {s['minimum']}..{s['maximum']}"
    if lo and hi:
        return f" {lo} and {hi}"
    return f" {lo or hi}" if (lo or hi) else ""


def describe(schema: dict, root: dict | None = None) -> str:
    """What a (sub)schema allows, in words: ``an integer in 1..4``, ``one of H, L2``, …"""
    root = root or schema
    s = _resolve(schema, root)
    if "oneOf" in s or "anyOf" in s:
        return " or ".join(describe(sub, root) for sub in s.get("oneOf", s.get("anyOf")))
    if "enum" in s:
        return "one of " + ", ".join(str(v) for v in s["enum"])
    t = s.get("type")
    if t == "integer":
        return "an integer" + _number_range(s)
    if t == "number":
        return "a finite number" + _number_range(s)
    if t == "string":
        return "a string" + (f" matching {s['pattern']}" if "pattern" in s else "") + (
            f" ({s['description']})" if "description" in s else "")
    if t == "array":
        lo, hi = s.get("minItems"), s.get("maxItems")
        size = (f"{lo} " if lo == hi and lo is not None else
                f"{lo}+ " if lo else f"at most {hi} " if hi else "")
        uniq = "distinct " if s.get("uniqueItems") else ""
        items = describe(s.get("items", {}), root) if s.get("items") else "anything"
        return f"a list of {size}{uniq}items, each {items}"
    if t == "object":
        props = list(s.get("properties", {}))
        extra = s.get("additionalProperties", True)
        if props and extra is False:
            return "a mapping with the keys " + ", ".join(props)
        if isinstance(extra, dict):
            return f"a mapping of names to {describe(extra, root)}"
        return "a mapping"
    return "see workflow/schemas/config.schema.yaml"


_VALIDATOR: list = [None, None]
"""The last schema and its validator: a config check (a process, a test of thousands of configs)
validates against the same schema dict again and again; building the validator is a third of it."""


def _validator(schema: dict):
    if _VALIDATOR[0] is not schema:  # identity, not equality: the dict this validator holds
        _VALIDATOR[:] = [schema, _new_validator(schema)]
    return _VALIDATOR[1]


def _new_validator(schema: dict):
    import jsonschema

    base = jsonschema.Draft202012Validator
    # 4.0 is an integer in JSON Schema; here it is not: it would reach the jobs as a float
    checker = base.TYPE_CHECKER.redefine(
        "integer", lambda _checker, x: isinstance(x, int) and not isinstance(x, bool))
    return jsonschema.validators.extend(base, type_checker=checker)(schema)


def schema_error(cfg, schema: dict) -> ConfigError | None:
    """The most relevant schema violation as a one-line :class:`ConfigError`, or None."""
    from jsonschema.exceptions import best_match

    err = best_match(_validator(schema).iter_errors(cfg))
    if err is None:
        return None
    path = list(err.absolute_path)
    sub = _resolve(err.schema, schema)
    if err.validator == "required":
        missing = [r for r in err.validator_value if r not in err.instance]
        name = missing[0] if missing else "?"
        sub_prop = _resolve(sub.get("properties", {}).get(name, {}), schema)
        return ConfigError(key_path([*path, name]), "missing (required)",
                           allowed=describe(sub_prop, schema) if sub_prop else None)
    if err.validator == "additionalProperties":
        known = list(sub.get("properties", {}))
        extra = [key for key in err.instance if key not in known] if isinstance(err.instance, dict) else []
        name = extra[0] if extra else "?"
        return ConfigError(key_path([*path, name]), f"unknown key ({name!r} was unexpected)",
                           allowed=f"the keys of {key_path(path)}: " + ", ".join(known))
    if "propertyNames" in err.schema_path:  # a key that is not a plain name (it may become a path)
        return ConfigError(key_path(path), f"the key {show(err.instance)} is not a plain name (a key here names "
                           "a folder or a column, never a path)", allowed=describe({"type": "string", **sub}, schema))
    return ConfigError(key_path(path), err.message, got=err.instance, allowed=describe(sub, schema))
