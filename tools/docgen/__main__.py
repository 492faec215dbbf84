import sys

from tools.docgen.main import main

sys.exit(main())
