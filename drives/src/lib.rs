//! CANopen CiA-402 master over SocketCAN. Filled by issue 3 ("CANopen CiA-402 master").
