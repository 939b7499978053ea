from frog_bt.cli import main

raise SystemExit(main())
