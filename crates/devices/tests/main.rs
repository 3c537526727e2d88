//! The device gateway's runtime without a server: the shipped device lists against the
//! catalogs their scenarios' served configurations give, and the endpoints as a driver sees
//! them (a pseudo-terminal opened through its link, in raw mode; TCP; UDP), and the outbox's
//! timing and bounds.

mod catalog;
mod endpoints;
mod lockstep;
mod outbox;
