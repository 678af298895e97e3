"""The run log: the MCAP writer and its live view, the readers, the encoding, recovery, replay and verification.

Writing: :mod:`.writer` (the recorder a run hands its steps to) builds messages with :mod:`.messages` and
:mod:`.encoding` into a :mod:`.file`, on the channels of :mod:`.format`; :mod:`.live_view` and :mod:`.pacing`
serve the same messages to Foxglove while a run happens.  Reading: :mod:`.records` walks the file record by
record, :mod:`.reader` turns it into columns (:mod:`.columns`), :mod:`.summary` answers from the summary
section, :mod:`.recover` rewrites a cut file.  :mod:`.replay` renders or re-simulates a log and
:mod:`.verify_report` compares the two; :mod:`.foxglove_layout` is the layout to view a log with.
Nothing here imports the command line.
"""
