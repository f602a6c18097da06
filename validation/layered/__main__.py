"""``python -m validation.layered [--part NAME ...]``: the layered studies in turn (see the
package docstring)."""
import argparse
import importlib
import time

PARTS = ("crosscheck", "slider", "film", "render", "benchmark")


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m validation.layered",
                                 description="Coated and layered substrates: the studies")
    ap.add_argument("--part", action="append", choices=sorted(PARTS))
    args = ap.parse_args(argv)
    for name in args.part or PARTS:
        t0 = time.perf_counter()
        importlib.import_module(f"validation.layered.{name}").main()
        print(f"[{name}: {time.perf_counter() - t0:.0f} s]", flush=True)


if __name__ == "__main__":
    main()
