"""``python -m cartpole_q`` runs the command line."""

from cartpole_q.cli import main

main()
