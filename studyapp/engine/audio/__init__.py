"""What is heard: the audio sinks (sinks.py), their FIFO (fifo.py), WAV files (wav.py), the session's recorder (recorder.py)."""
