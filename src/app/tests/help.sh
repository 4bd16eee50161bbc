#!/usr/bin/env bash
# Every subcommand answers --help with exit 0, and a bad subcommand fails with a message.
set -euo pipefail
panoptes=$1
"$panoptes" --help | grep "Panoptes" >/dev/null
"$panoptes" --version | grep "panoptes" >/dev/null
for sub in $("$panoptes" --help | awk '/^SUBCOMMANDS:/{f=1;next} f&&NF{print $1}'); do
  "$panoptes" "$sub" --help >/dev/null || { echo "'$sub --help' failed"; exit 1; }
done
if "$panoptes" no-such-command 2>/dev/null; then echo "unknown subcommand accepted"; exit 1; fi
echo "help: ok"
