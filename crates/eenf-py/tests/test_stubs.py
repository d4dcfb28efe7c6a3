"""The type stubs name every keyword parameter the library takes, with its default: they are
checked against the option sets the native module fills (the command line's)."""

import ast
import json
from pathlib import Path

import eenf
from eenf import _eenf

STUB = Path(eenf.__file__).with_name("__init__.pyi")
SETS = {"read_events": ["input"], "iter_events": ["input"], "info": ["input"],
        "extract": ["extract"], "reference": ["reference"], "video": ["video"],
        "match": ["match"], "simulate": ["simulate"], "simulate_dataset": ["simulate_dataset"], "write_events": ["write"],
        "edits": ["edits"], "refdb_build": ["refdb_build"]}


def stub_functions():
    tree = ast.parse(STUB.read_text())
    out = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            a = node.args
            names = [x.arg for x in a.args + a.kwonlyargs]
            defaults = dict(zip([x.arg for x in a.args][len(a.args) - len(a.defaults):], a.defaults))
            defaults.update({x.arg: d for x, d in zip(a.kwonlyargs, a.kw_defaults) if d is not None})
            out[node.name] = (names, {k: ast.literal_eval(v) for k, v in defaults.items()})
    return out


def test_stubs_match_the_option_sets():
    stubs = stub_functions()
    for fn, sets in SETS.items():
        names, defaults = stubs[fn]
        for s in sets:
            for o in json.loads(_eenf.options(s)):
                name, default = o["name"], o["default"]
                assert name in names, f"{fn}: {name} missing from the stub"
                # output: None stands for the command line's default name
                if default is None or o["switch"] or name == "output":
                    continue
                d = defaults[name]
                assert str(d) == default or (isinstance(d, float) and d == float(default)), (fn, name, d, default)


def test_every_public_name_has_a_stub_and_a_docstring():
    stubs = stub_functions()
    text = STUB.read_text()
    for name in eenf.__all__:
        obj = getattr(eenf, name)
        if callable(obj) and not isinstance(obj, type):
            assert name in stubs, name
        else:
            assert name in text, name
        assert getattr(obj, "__doc__", None) or name == "EVENT_DTYPE", name
