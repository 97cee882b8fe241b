"""Files the way nylonflex writes and reads them, below every layer that does.

- :mod:`.atomic`: the one atomic writer (a temporary, fsync, rename, fsync of the folder),
  and the refusals of links, FIFOs and special files at any output path;
- :mod:`.safe_yaml`: bounded YAML (size, depth, aliases, duplicate keys);
- :mod:`.material_files`: the fitted material files (``kind: silicone``, ``nylon``,
  ``chamber``) a config names.

They import nothing of nylonflex but :mod:`nylonflex.units` and the version.
"""
