"""Run the command line: ``python -m laplace_springs``."""

from laplace_springs.cli import main

raise SystemExit(main())
