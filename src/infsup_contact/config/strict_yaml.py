"""A strict reading of the workflow's config files, in front of Snakemake's own loader.

Snakemake reads a config file as JSON or else as YAML 1.1 (PyYAML through yte), and three
YAML 1.1 rules turn a plausible file into other values without a word:

* a key given twice keeps the second value;
* a zero-padded integer is octal (``N: [004, 010]`` is ``[4, 8]``), or a string where it is
  not a valid octal (``09``);
* a float needs a dot *and* a signed exponent: ``1e3`` and ``1.0e3`` are strings
  (``1.0e+3`` and ``1000`` are numbers).

:func:`check_config_file` re-reads each file as a node tree (``yaml.compose``: values with their
line numbers, nothing constructed) and refuses these with one line naming the key, the file and
the line: a :class:`~infsup_contact.config.checks.ConfigError`. ``workflow/rules/common.smk``
runs it on ``workflow.configfiles`` before :func:`~infsup_contact.config.checks.check_config`.
A JSON file (Snakemake tries JSON first) is checked for duplicate keys only: JSON has neither
octal nor the exponent rule.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

from .checks import ConfigError, key_path

ZERO_PADDED = re.compile(r"[-+]?0[0-9_]+")
"""A plain scalar YAML 1.1 reads as octal (or as a string when a digit is 8 or 9)."""
STR_TAG = "tag:yaml.org,2002:str"


def _looks_numeric(text: str) -> bool:
    """Python reads ``text`` as a finite or infinite float (``1e3``, ``1.0e3``, ``inf``)."""
    try:
        float(text.replace("_", "x"))  # '1_000' is an int in YAML 1.1 already; keep it out of here
    except ValueError:
        return False
    return True


def yaml_number(value: float) -> str:
    """``value`` spelled so that YAML 1.1 reads a number: 1000, 1.0e-06, 2.5e+20, .inf."""
    import math

    if not math.isfinite(value):
        return ".nan" if math.isnan(value) else ("-.inf" if value < 0 else ".inf")
    if value == int(value) and abs(value) < 1e15:
        return str(int(value))
    if "e" not in repr(value):  # 0.5: already a YAML float
        return repr(value)
    mantissa, exponent = f"{value:e}".split("e")
    mantissa = mantissa.rstrip("0")
    return f"{mantissa}0e{exponent}" if mantissa.endswith(".") else f"{mantissa}e{exponent}"


def _scalar_problem(node, path, where) -> ConfigError | None:
    """The quirk a plain (unquoted) scalar value falls into, if any."""
    import yaml

    if not isinstance(node, yaml.ScalarNode) or node.style is not None:  # quoted: the user meant a string
        return None
    text = node.value
    if ZERO_PADDED.fullmatch(text):
        read = yaml.safe_load(text)
        return ConfigError(key_path(path), f"zero-padded number {text} ({where}): YAML 1.1 reads it as "
                           + (f"the octal number {read}" if isinstance(read, int) else f"the string {read!r}"),
                           allowed=f"{int(text.replace('_', ''), 10)} written without leading zeros")
    if node.tag == STR_TAG and _looks_numeric(text):
        return ConfigError(key_path(path), f"{text} is read as a string, not a number ({where}): YAML 1.1 "
                           "reads a float only with a dot and a signed exponent",
                           allowed=f"{yaml_number(float(text))} (or quote it if a string is meant)")
    return None


def _walk(node, path, file: str) -> None:
    """Depth-first over the node tree: duplicate keys, then the scalar quirks."""
    import yaml

    where = f"{file} line {node.start_mark.line + 1}"
    if isinstance(node, yaml.MappingNode):
        seen = {}
        for key_node, value_node in node.value:
            key = key_node.value if isinstance(key_node, yaml.ScalarNode) else str(key_node)
            if key in seen:
                raise ConfigError(key_path([*path, key]), f"given twice ({file} lines {seen[key]} and "
                                  f"{key_node.start_mark.line + 1}; YAML would keep the second silently)",
                                  allowed="each key once")
            seen[key] = key_node.start_mark.line + 1
            _walk(value_node, [*path, key], file)
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            _walk(item, [*path, i], file)
    else:
        err = _scalar_problem(node, path, where)
        if err is not None:
            raise err


def _json_duplicates(pairs):
    """``object_pairs_hook`` refusing a key given twice."""
    keys = [k for k, _ in pairs]
    for key in keys:
        if keys.count(key) > 1:
            raise ConfigError(key, "given twice in a JSON config (the second would be kept silently)",
                              allowed="each key once")
    return dict(pairs)


def check_config_file(path) -> None:
    """Refuse the YAML 1.1 quirks of the module docstring in one config file.

    Raises
    ------
    ConfigError
        One line naming the key, the file and the line. A file that is neither JSON nor YAML
        is left to Snakemake's own message.
    """
    import yaml

    text = Path(path).read_text(encoding="utf-8")
    try:
        json.loads(text, object_pairs_hook=_json_duplicates)
        return  # Snakemake reads it as JSON
    except ValueError as err:
        if isinstance(err, ConfigError):
            raise
    from ..yaml_limits import YamlLimitError, compose

    try:
        root = compose(text, duplicates=False)  # an alias expansion refused here (yaml_limits), the rest below
    except YamlLimitError as err:
        raise ConfigError(err.key or "(document)", f"{err.problem} ({path} line {err.line})",
                          allowed="aliases expanding to a bounded document") from None
    except yaml.YAMLError:
        return
    if root is not None:
        _walk(root, [], str(path))


def check_config_files(paths) -> None:
    """:func:`check_config_file` for each file Snakemake loaded (``workflow.configfiles``)."""
    for path in paths:
        check_config_file(path)
