"""Run one page's blocks in the current folder (a subprocess of the docs tests).

Usage: ``python run_blocks.py PAGE``. Exits non-zero naming the first block that fails.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
import traceback
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from code_blocks import code_blocks  # noqa: E402


def main(page: str) -> int:
    namespace: dict[str, object] = {"__name__": "__main__"}
    for block in code_blocks(Path(page).read_text(encoding="utf-8")):
        where = f"{page}:{block.line} ({block.lang})"
        print(f"--- {where}", flush=True)
        if os.environ.get("VC_GYM_DOCS_TIMES"):  # where a page's test spends its time
            print(f"@@@ {where} starts at {time.monotonic():.1f}", file=sys.stderr, flush=True)
        if block.lang == "python":
            try:
                exec(compile(block.code, where, "exec"), namespace)  # noqa: S102
            except BaseException:
                traceback.print_exc()
                print(f"FAILED: {where}", file=sys.stderr)
                return 1
        else:
            done = subprocess.run(["bash", "-euo", "pipefail", "-c", block.code], env=os.environ)
            if done.returncode != 0:
                print(f"FAILED: {where} exited {done.returncode}", file=sys.stderr)
                return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
