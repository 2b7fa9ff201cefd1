"""PyCRAM: concurrent, reactive plans for mobile manipulation robots."""


def __getattr__(name: str):  # lazy exports: `import pycram` stays fast and side-effect free
    if name == "perform":
        from pycram.designator import perform

        return perform
    raise AttributeError(f"module 'pycram' has no attribute {name!r}")
