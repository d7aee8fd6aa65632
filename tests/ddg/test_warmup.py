"""`python -m ddg warmup` compiles every model's kernels: a model it leaves out compiles them in the
user's first run instead (the cross-section ribbon's took 80 s and 2.2 GB of memory, measured)."""
import subprocess
import sys

import pytest

from ddg import api, warmup


class Built(Exception):
    """Raised by a stand-in model class: the warm-up part built the model."""


def test_the_warmup_has_a_part_for_every_model_the_api_offers(monkeypatch):
    """Each model the api offers is a warm-up part, and that part builds the model's own class
    (the registry's, replaced here by a stand-in that says it was built)."""
    import dataclasses

    from ddg.models import registry

    assert set(api.DEFAULT_RESOLUTION) <= set(warmup.PARTS)
    for name in api.DEFAULT_RESOLUTION:
        def stand_in(*args, _name=name, **kwargs):
            raise Built(_name)

        monkeypatch.setitem(registry.MODELS, name, dataclasses.replace(registry.MODELS[name], model_class=stand_in))
        with pytest.raises(Built, match=f"^{name}$"):
            warmup.compile_part(name)


def test_an_unknown_part_or_job_count_is_refused_in_one_line():
    for argv in (["warmup", "spaghetti"], ["warmup", "--jobs", "0"]):
        done = subprocess.run([sys.executable, "-m", "ddg", *argv], capture_output=True, text=True, timeout=60)
        assert done.returncode == 2
        assert len(done.stderr.strip().splitlines()) == 1, done.stderr
