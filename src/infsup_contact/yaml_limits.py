"""One YAML loader for every file a user hands in (system manifests, workflow configs).

``yaml.safe_load`` builds no objects a file did not ask for, but two things still pass:

* a key given twice keeps the second value without a word (``h``, ``norm``);
* aliases: nine anchors of nine aliases each (a 400-byte "billion laughs" file) are 9⁹ values
  once anything walks or prints the data — ``repr`` in an error message took gigabytes
  before it failed with a MemoryError.

:class:`LimitedLoader` is a ``SafeLoader`` that checks the node tree of each document before
anything is constructed: every mapping's keys once, and the tree as expanded through its aliases
at most :data:`MAX_NODES` nodes (counted once per distinct node, so the check is linear in the
file); a file that holds that many values without any alias is refused saying so (the size of its
list), not blamed on aliases. A recursive alias is refused too. The problems are :class:`YamlLimitError`, whose
``key`` is the path of the offending key (``levels[0].h``) and ``line`` its 1-based line.
"""
from __future__ import annotations

import yaml

MAX_NODES = 100_000
"""Most nodes a document may hold once its aliases are expanded (a 3-level manifest has ~20;
``config/config.yaml`` a few hundred)."""


class YamlLimitError(yaml.YAMLError):
    """A key given twice, aliases that expand too far, or a file holding more than
    :data:`MAX_NODES` values: ``problem``, ``key`` (a path), ``line``."""

    def __init__(self, problem: str, key: str = "", line: int | None = None):
        self.problem, self.key, self.line = problem, key, line
        super().__init__(problem)


def _path(parts) -> str:
    out = ""
    for p in parts:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out


def check_nodes(root, max_nodes: int = MAX_NODES, duplicates: bool = True) -> None:
    """Refuse duplicate keys (unless ``duplicates`` is False) and an expansion beyond
    ``max_nodes`` in a composed node tree."""
    sizes: dict[int, int] = {}
    active: set[int] = set()
    aliased: set[int] = set()  # nodes holding an alias (PyYAML composes one as the anchored node itself)

    def size(node, path) -> int:
        key = id(node)
        if key in sizes:
            aliased.update(active)
            return sizes[key]
        if key in active:
            raise YamlLimitError("a recursive alias (a node that contains itself)", _path(path),
                                 node.start_mark.line + 1)
        active.add(key)
        total = 1
        if isinstance(node, yaml.MappingNode):
            seen = {}
            for key_node, value_node in node.value:
                name = key_node.value if isinstance(key_node, yaml.ScalarNode) else f"<{key_node.tag}>"
                line = key_node.start_mark.line + 1
                if duplicates and key_node.tag != "tag:yaml.org,2002:merge":
                    if name in seen:
                        raise YamlLimitError(f"key {name!r} given twice (lines {seen[name]} and {line}; YAML would "
                                             "keep the second value silently)", _path([*path, name]), line)
                    seen[name] = line
                total += size(key_node, path) + size(value_node, [*path, name])
                if total > max_nodes:
                    break
        elif isinstance(node, yaml.SequenceNode):
            for i, item in enumerate(node.value):
                total += size(item, [*path, i])
                if total > max_nodes:
                    break
        if total > max_nodes and key in aliased:
            raise YamlLimitError(f"its aliases expand to more than {max_nodes:,} values (a 'billion laughs' "
                                 "file?); write the values out, or use fewer aliases", _path(path),
                                 node.start_mark.line + 1)
        if total > max_nodes:  # no alias: the file itself is that large
            what = (f"a list of {len(node.value):,} items" if isinstance(node, yaml.SequenceNode) and
                    len(node.value) > max_nodes else "more")
            raise YamlLimitError(f"{what}: more than the {max_nodes:,} values read from one file (a few levels or "
                                 "settings hold far fewer); is this the right file?", _path(path),
                                 node.start_mark.line + 1)
        active.discard(key)
        sizes[key] = total
        return total

    size(root, [])


class LimitedLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` with :func:`check_nodes` on every document (module docstring)."""

    max_nodes = MAX_NODES
    duplicates = True

    def compose_document(self):
        node = super().compose_document()
        if node is not None:
            check_nodes(node, self.max_nodes, self.duplicates)
        return node


class ExpansionLoader(LimitedLoader):
    """:class:`LimitedLoader` checking the expansion only (a caller that reports duplicate keys
    itself, with its own wording: :mod:`infsup_contact.config.strict_yaml`)."""

    duplicates = False


def load(text):
    """``yaml.safe_load`` with the checks of :class:`LimitedLoader`."""
    return yaml.load(text, Loader=LimitedLoader)  # noqa: S506 - a SafeLoader subclass


def compose(text, duplicates: bool = True):
    """``yaml.compose`` (the node tree, nothing constructed) with the same checks (duplicate
    keys left to the caller when ``duplicates`` is False)."""
    return yaml.compose(text, Loader=LimitedLoader if duplicates else ExpansionLoader)
