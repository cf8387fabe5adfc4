// placeholder until the map tools land
int main() { return 2; }
