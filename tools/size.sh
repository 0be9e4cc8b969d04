#!/bin/sh
# Flash and static RAM of every firmware build under the given folder.
# flash = .text + .data (initialised data is stored in flash too);
# static RAM = .data + .bss.
set -e
dir=${1:-build}
printf '%-16s %10s %12s\n' build "flash (B)" "static RAM (B)"
for elf in "$dir"/*-*/orfa.elf; do
	[ -f "$elf" ] || continue
	avr-size "$elf" | awk -v name="$(basename "$(dirname "$elf")")" \
		'NR == 2 { printf "%-16s %10d %12d\n", name, $1 + $2, $2 + $3 }'
done
