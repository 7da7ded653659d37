"""``python -m vc_gym.cli``: the ``vc-gym`` command."""

import sys

from vc_gym.cli import main

sys.exit(main())
