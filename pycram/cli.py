def main() -> None:  # replaced by the real CLI
    raise SystemExit("pycram CLI not built yet")
