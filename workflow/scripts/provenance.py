"""Write results/provenance.json atomically (versions, git commit, platform, date)."""
import json
import sys

from infsup_contact.io import write_atomic
from infsup_contact.provenance import provenance

write_atomic(sys.argv[1], json.dumps(provenance(), indent=2) + "\n")
