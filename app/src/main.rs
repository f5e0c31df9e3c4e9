fn main() {
    println!("anthesis: being written");
}
