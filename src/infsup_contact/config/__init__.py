"""The workflow configuration checked before any job: its files read strictly (`strict_yaml`), the
schema (`schema`), the cross-key rules (`checks`, `meshes`, `membranes3d`, `elastic3d`) and the memory a
request needs (`memory`)."""
