"""Reading a YAML config file: its size (:data:`MAX_CONFIG_BYTES`), its parsing with the safe loader and
duplicate keys refused (:func:`parse_yaml`, :func:`read_yaml`), and the one-line field paths and texts
(:func:`one_line`, :func:`field_path`) the refusals of a config (:data:`ConfigError`) are written with.
"""
from __future__ import annotations

from pathlib import Path

import yaml

from ..errors import InputError


def one_line(text) -> str:
    """``text`` with its whitespace runs (newlines included) collapsed to single spaces."""
    return " ".join(str(text).split())


def field_path(loc) -> str:
    """A pydantic ``loc`` (or any sequence of keys) as ``a.b.c``, one line."""
    return ".".join(one_line(p) if isinstance(p, str) and p.isprintable() else
                    (str(p) if isinstance(p, int) else repr(p)) for p in loc)


# --------------------------------------------------------------------------- YAML files

MAX_CONFIG_BYTES = 16 * 2**20
"""A config file larger than this (16 MiB) is refused unread: it is not a config."""

_MERGE_TAG = "tag:yaml.org,2002:merge"


def _no_duplicate_keys(loader: yaml.SafeLoader, root: yaml.Node, src: str) -> None:
    """InputError naming the key path when a mapping repeats a key (YAML would keep the last silently)."""
    stack = [(root, ())]
    done: set[int] = set()
    while stack:
        node, path = stack.pop()
        if id(node) in done:
            continue
        done.add(id(node))
        if isinstance(node, yaml.MappingNode):
            first: dict = {}
            for k, v in node.value:
                if not isinstance(k, yaml.ScalarNode):  # a complex key: the constructor refuses it
                    stack.append((v, path + ("?",)))
                    continue
                if k.tag == _MERGE_TAG:
                    stack.append((v, path))
                    continue
                key = loader.construct_object(k, deep=True)
                try:
                    line = first.get(key)
                except TypeError:  # unhashable: the constructor refuses it
                    line = None
                if line is not None:
                    raise InputError(src, field_path(path + (key,)),
                                     f"duplicate key (lines {line + 1} and {k.start_mark.line + 1}); "
                                     "YAML would silently keep the last")
                try:
                    first[key] = k.start_mark.line
                except TypeError:
                    pass
                stack.append((v, path + (key,)))
        elif isinstance(node, yaml.SequenceNode):
            for i, v in enumerate(node.value):
                stack.append((v, path + (i,)))


def parse_yaml(text: str, source: str = "<text>"):
    """Parse one YAML document with the safe loader, refusing duplicate keys; InputError when malformed."""
    src = str(source)
    loader = None
    try:
        loader = yaml.SafeLoader(text)
        node = loader.get_single_node()
        if node is None:
            return None
        _no_duplicate_keys(loader, node, src)
        return loader.construct_document(node)
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f"line {mark.line + 1}" if mark is not None else ""
        problem = getattr(e, "problem", None) or e
        raise ConfigError(src, where, f"malformed YAML ({one_line(problem)})") from None
    except RecursionError:
        raise ConfigError(src, "", "malformed YAML (nested too deeply)") from None
    except (ValueError, TypeError, OverflowError) as e:  # a constructor's: a date 2020-13-45, '!!int 1.5'
        raise ConfigError(src, "", f"malformed YAML (a value cannot be read: {one_line(e)})") from None
    finally:
        if loader is not None:
            loader.dispose()


def read_yaml(path: str | Path, empty_ok: bool = False) -> dict:
    """Read a YAML mapping from a file.

    Duplicate keys are refused (YAML's "the last wins" would hide a typo), and so are a
    missing file, a directory, a file that is not UTF-8 text, malformed YAML and a file over
    :data:`MAX_CONFIG_BYTES`.

    Parameters
    ----------
    path : str or os.PathLike
    empty_ok : bool, default False
        An empty file gives ``{}`` instead of an error.

    Raises
    ------
    mmg.errors.InputError
        One line naming the file (and the line or key at fault).
    """
    src = str(path)
    try:
        with open(path, "rb") as fh:
            raw = fh.read(MAX_CONFIG_BYTES + 1)
    except FileNotFoundError:
        raise ConfigError(src, "", "file not found") from None
    except IsADirectoryError:
        raise ConfigError(src, "", "is a directory, not a YAML file") from None
    except PermissionError:
        raise ConfigError(src, "", "cannot be read (permission denied)") from None
    except (OSError, ValueError) as e:
        raise ConfigError(src, "", f"cannot be read ({one_line(getattr(e, 'strerror', None) or e)})") from None
    if len(raw) > MAX_CONFIG_BYTES:
        raise ConfigError(src, "", f"larger than {MAX_CONFIG_BYTES // 2**20} MiB: not a config file")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise ConfigError(src, "", f"not a UTF-8 text file (byte 0x{raw[e.start]:02x} at offset {e.start}): "
                                   "is it binary?") from None
    data = parse_yaml(text, src)
    if data is None and empty_ok:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(src, "", "expected a mapping at the top level")
    return data


ConfigError = InputError
"""Bad configuration: alias of :class:`mmg.errors.InputError`."""
