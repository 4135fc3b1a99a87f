"""Command-line layer of :mod:`qualgrasp.certify`.

* :mod:`.options`: the checks every command of every half makes before it works (output paths,
  numeric options) and its one-line refusal (:func:`~.options.fail`, exit code 2);
* :mod:`.commands`: ``qualgrasp certify``, ``verify``, ``certify-regions`` and ``sample``
  (:func:`register` adds them to the ``qualgrasp`` application).
"""

from .commands import register

__all__ = ["register"]
