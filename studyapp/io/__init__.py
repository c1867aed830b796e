"""Files in and out: written whole or not at all, read with checks, one line naming what is wrong.

    atomic.atomic_open / atomic_path     write a file whole or not at all (temporary file, fsync, rename)
    own_files.open_own                   write in a data folder only a file the app made (no links)
    small_files.open_regular             read a small text file a person wrote, refusing devices and FIFOs
    small_files.read_json                a small JSON file, its size and nesting bounded
    bounded_json.loads                   JSON with its nesting depth bounded before it is parsed
    special_files.refuse_special         FIFOs, devices and sockets refused from their status, before opening
    file_bounds                          sparse files and sizes refused from their status, before reading
    archive_bounds                       .npz and .h5 members bounded from their directory, before unpacking
    sample_table                         CSV tables of samples, read a block at a time
    recording.save / recording.load      signal recordings (.h5, .npz, .csv) with their metadata
    recording_blocks.RecordingBlocks     a recording (.npz or .h5) read a block at a time

The package name shadows the standard library's ``io`` only as ``studyapp.io``:
every import in studyapp is absolute, so ``import io`` still means the standard library.
"""
