"""The tests' minimal hosts (emulator_process.Host, loop_host.LoopHost) lose nothing a device sent: what a ``wait``
read after the message it waited for comes out of the next ``poll``. A lock-step device sends a row and waits for
its answer, so a row read together with a State and dropped hung the suite for the hang guard's 600 s (the
lock-step equality test, 1 run in 2 beside two ``yes``)."""

import os
import pty
import tty

import pytest

from studyapp.device import messages
from studyapp.device.streams import Sender, host_receiver
from tests.device.emulator_process import Host
from tests.device.loop_host import LoopHost


@pytest.mark.parametrize("kind", [Host, LoopHost])
def test_a_row_read_with_the_awaited_state_comes_out_of_the_next_poll(kind):
    master, slave = pty.openpty()
    tty.setraw(master)
    try:
        host = kind(os.ttyname(slave))
        if kind is LoopHost:  # the channels are INFO's, which this test skips
            host.channels = messages.SI_CHANNELS
        else:
            host.receiver = host_receiver(messages.SI_CHANNELS)
        row = messages.Sensors(sample=7, flags=1, values=((0.001, 0.5, 0.25),))
        sender = Sender()
        os.write(master, sender.frame(messages.State(armed=1)) + sender.frame(row))  # one read takes both
        assert host.wait(messages.State, where=lambda m: m.armed).armed == 1
        assert host.next(timeout=1.0) == [row]
        with pytest.raises(AssertionError, match="nothing from the device within 0.2 s"):
            host.next(timeout=0.2)
        host.close()
    finally:
        os.close(master)
        os.close(slave)
