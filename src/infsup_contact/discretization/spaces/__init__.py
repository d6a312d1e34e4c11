"""The registry of multiplier spaces as data (``registry``), the face-only entries
(``face_entries``) and the loader of users' spaces (``user_spaces``)."""
