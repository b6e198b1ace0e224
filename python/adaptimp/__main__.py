"""``python -m adaptimp``: the same as the ``adaptimp`` command."""

from .cli import main

raise SystemExit(main())
