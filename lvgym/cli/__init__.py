"""The command layer: the console script ``lvgym`` and the commands of the benchmark. It sits on top of
every other layer, and nothing of lvgym imports it but its own modules and the entry scripts
(``python -m lvgym``, ``evaluate.py``, ``train.py``); ``tests/test_layers.py`` checks it.

- :mod:`.main`: the console script ``lvgym`` (``lvgym --help`` lists the commands);
- :mod:`.evaluate`, :mod:`.margins`, :mod:`.fingerprint`: the benchmark's commands, with the options the
  flight commands share (:mod:`.flights`); the benchmark layer itself builds no parser;
- :mod:`.policies`: importing it registers every built-in policy with the benchmark's registry.

The helpers every command line uses (a command line declared as a dataclass, the one-line refusals, the
subcommands) are :mod:`lvgym.commandline`, beside the layers, so that any layer may declare its own
command line; :mod:`.args` repeats its names for scripts written against the old place.
"""
