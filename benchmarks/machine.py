"""What a benchmark's JSON records about the machine it ran on (shared by the scripts)."""

from __future__ import annotations

import os
import platform
from typing import Any


def machine() -> dict[str, Any]:
    """CPUs, platform, Python and the load averages now (others may be running too)."""
    loads = list(os.getloadavg())
    return {
        "cpus": os.cpu_count(),
        "platform": platform.platform(),
        "python": platform.python_version(),
        "load_average": loads[0],
        "load_averages_1_5_15_min": loads,
    }
