"""`python -m apair.cli`, the same as `python -m apair`."""

from .app import main

raise SystemExit(main())
