"""The requests of jobs (``batch``, ``search``, ``compare``, ``eval``) as the extension
reads them: keyword arguments to the JSON text of the library's request
(``BatchRequest``, ``SearchRequest``, ``CompareRequest``, ``EvalRequest``), whose
defaults, checks, agent choice and run identity are the command line's. A bad field raises ``ValueError`` naming the field (``train_seeds:
...``); ``python -m unforeseen.distributed`` spells it as its flag (:func:`flag_message`).

:data:`BATCH_DEFAULTS`, :data:`SEARCH_DEFAULTS`, :data:`COMPARE_DEFAULTS` and
:data:`EVAL_DEFAULTS` are the requests' fields with their defaults, read from the
library: :func:`unforeseen.batch`, :func:`unforeseen.distributed.run_batch`,
:func:`unforeseen.search`, :func:`unforeseen.distributed.run_search`,
:func:`unforeseen.compare` and :func:`unforeseen.evaluate_builtin` take these fields with
these defaults (a test checks their signatures against them), and the Ray driver's
command line derives its options from them.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from typing import Any

from . import _unforeseen

#: The batch request's fields and their defaults (``unforeseen batch``'s).
BATCH_DEFAULTS: dict[str, Any] = json.loads(_unforeseen.request_defaults("batch"))

#: The search request's fields and their defaults (``unforeseen search``'s).
SEARCH_DEFAULTS: dict[str, Any] = json.loads(_unforeseen.request_defaults("search"))

#: The compare request's fields and their defaults (``unforeseen compare``'s).
COMPARE_DEFAULTS: dict[str, Any] = json.loads(_unforeseen.request_defaults("compare"))

#: The eval request's fields and their defaults (``unforeseen eval``'s).
EVAL_DEFAULTS: dict[str, Any] = json.loads(_unforeseen.request_defaults("eval"))

#: Fields whose flag is not ``--`` and the field with ``-`` for ``_``.
_FLAGS = {"maps": "MAP", "methods": "--method", "sets": "--set"}


def flag(field: str) -> str:
    """The command line's flag of a request's field: ``train_seeds`` -> ``--train-seeds``."""
    return _FLAGS.get(field, "--" + field.replace("_", "-"))


def flag_message(message: str, fields: Mapping[str, Any]) -> str:
    """An error message that starts with a request's field (``train_seeds: ...``),
    with the field spelt as its flag (``--train-seeds: ...``), as the command line
    prints it."""
    head = message.split(" ", 1)[0].split(":", 1)[0]
    if head in fields:
        return flag(head) + message[len(head):]
    return message


def _plain(value: Any) -> Any:
    """A keyword argument's value as JSON: paths as text, sequences and ranges as lists."""
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, (str, bytes, bool, int, float)) or value is None:
        return value
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    try:
        return [_plain(v) for v in value]
    except TypeError:
        return value


def request_json(fields: Mapping[str, Any]) -> str:
    """The JSON text of a request with ``fields`` (the others at their defaults). A single
    map (text or path) given as ``maps`` is a list of one."""
    plain = {k: _plain(v) for k, v in fields.items()}
    if isinstance(plain.get("maps"), str):
        plain["maps"] = [plain["maps"]]
    return json.dumps(plain)
