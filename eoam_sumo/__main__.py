from eoam_sumo.cli import main

raise SystemExit(main())
