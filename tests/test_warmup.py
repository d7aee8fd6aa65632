"""`python -m ddg warmup` compiles every model's kernels: a model it leaves out compiles them in the
user's first run instead (the cross-section ribbon's took 80 s and 2.2 GB of memory, measured)."""
import inspect

from ddg import api, warmup


def test_the_warmup_builds_every_model_the_api_offers():
    source = inspect.getsource(warmup.compile_kernels)
    for name in api.DEFAULT_RESOLUTION:
        cls = api._model_class(name)
        assert f"{cls.__name__}(" in source, f"{name} ({cls.__name__}) is not warmed up"
