"""Write the generated reference pages into the site (run by the mkdocs-gen-files plugin)."""

import mkdocs_gen_files

from cosim.reference.commands_page import commands_markdown
from cosim.reference.keys_page import keys_markdown
from cosim.reference.registries_page import registries_markdown
from cosim.reference.summary_page import summary_markdown
from cosim.reference.tables_page import tables_markdown

PAGES = {
    "reference/scenario-keys.md": keys_markdown,
    "reference/tables.md": tables_markdown,
    "reference/summary.md": summary_markdown,
    "reference/cli.md": commands_markdown,
    "reference/registries.md": registries_markdown,
}

for path, make in PAGES.items():
    with mkdocs_gen_files.open(path, "w") as page:
        page.write(make())
