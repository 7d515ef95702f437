"""The requests of jobs (``batch``, ``search``, ``compare``, ``eval``, ``estimate``) as the extension
reads them: the keyword arguments, as given, become the library's request
(``BatchRequest``, ``SearchRequest``, ``CompareRequest``, ``EvalRequest``,
``EstimateRequest``) in the
extension's conversion layer, whose defaults, checks, agent choice and run identity are
the command line's. A bad field raises ``ValueError`` naming the field (``train_seeds:
...``, ``episodes -5: expected a whole number in 1..=1000000``); ``python -m
unforeseen.distributed`` spells it as its flag (:func:`flag_message`).

:data:`BATCH_DEFAULTS`, :data:`SEARCH_DEFAULTS`, :data:`COMPARE_DEFAULTS`,
:data:`EVAL_DEFAULTS` and :data:`ESTIMATE_DEFAULTS` are the requests' fields with their defaults, read from the
library: :func:`unforeseen.batch`, :func:`unforeseen.distributed.run_batch`,
:func:`unforeseen.search`, :func:`unforeseen.distributed.run_search`,
:func:`unforeseen.compare`, :func:`unforeseen.evaluate_builtin` and
:func:`unforeseen.estimate` take these fields with
these defaults (a test checks their signatures against them), and the Ray driver's
command line derives its options from them, except the fields of
:data:`PYTHON_DEFAULTS`.
"""

from __future__ import annotations

import json
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

#: The estimate request's fields and their defaults (``unforeseen estimate``'s).
ESTIMATE_DEFAULTS: dict[str, Any] = json.loads(_unforeseen.request_defaults("estimate"))

#: The defaults the Python functions take where the command line's differ: no agent
#: cache unless one is given (``cache="out/agents"`` shares the command line's), so that a
#: call writes nothing it was not asked to write (``out=None`` writes no file at all).
PYTHON_DEFAULTS: dict[str, Any] = {"cache": None}

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
