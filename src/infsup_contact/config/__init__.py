"""The workflow configuration checked before any job: its files read strictly (`strict_yaml`), the
schema (`schema`), the cross-key rules (`checks`, `meshes`, `face`, `face_elastic`) and the memory a
request needs (`memory`)."""
