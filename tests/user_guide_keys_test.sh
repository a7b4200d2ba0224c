#!/bin/bash
# user_guide_keys_test.sh — the key table of docs/user-guide.md is the one the
# schema gives (`ibmdem keys`): a key added to a module without its row, or a
# changed default or range, fails here (regenerate with
# scripts/update_keys_doc.sh).  Prints TAP lines.
. "$(dirname "$0")/tap.sh"
T=$(mktemp -d /tmp/ibmdem_keys.XXXXXX)
"$BIN" keys > "$T/schema.md"
report $? "ibmdem keys prints the schema"
sed -n '/<!-- keys:begin/,/<!-- keys:end -->/p' docs/user-guide.md | sed '1d;$d' | sed '/^$/d' > "$T/doc.md"
sed '/^$/d' "$T/schema.md" > "$T/schema_nb.md"
if diff "$T/doc.md" "$T/schema_nb.md" > "$T/diff.txt"; then r=0; else r=1; head -20 "$T/diff.txt"; fi
report $r "docs/user-guide.md key table = ibmdem keys ($(grep -c '^| `' "$T/schema_nb.md") keys)"
tap_end "$T"
