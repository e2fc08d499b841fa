"""Run every ``bench/bench_*.py`` module's ``main()`` and write its dict to ``bench/results/<name>.json``.

``python -m bench.run_all [name ...]`` runs only the named benchmarks.
"""

from __future__ import annotations

import importlib
import json
import platform
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"


def main(argv: list[str] | None = None) -> int:
    names = argv if argv else sorted(p.stem[len("bench_"):] for p in HERE.glob("bench_*.py"))
    RESULTS.mkdir(exist_ok=True)
    for name in names:
        module = importlib.import_module(f"bench.bench_{name}")
        if hasattr(module, "available") and not module.available():
            print(f"bench {name}: skipped, it needs {module.available.__doc__.strip()}")
            continue
        t0 = time.perf_counter()
        result = module.main()
        result["_meta"] = {
            "wall_s": round(time.perf_counter() - t0, 2),
            "machine": platform.machine(),
            "python": platform.python_version(),
            "date": time.strftime("%Y-%m-%d %H:%M:%S"),
        }
        out = RESULTS / f"{name}.json"
        out.write_text(json.dumps(result, indent=2) + "\n")
        print(f"bench {name}: wrote {out.relative_to(HERE.parent)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
